//! Boundary nodes on the true geometry: edge nodes by arc length (Eq. (4)), approximate
//! geodesics on surfaces (Eq. (5), Fig. 3) and face-interior nodes (Eqs. (6)–(7)).
//!
//! Not yet implemented: this crate is filled in by issue [4/7].
