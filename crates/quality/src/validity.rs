//! Guaranteed validity from Bézier bounds on det J (beyond the paper, which samples det J
//! and notes that an inversion between sample points goes unnoticed).
//!
//! det J of an order-p element is a polynomial on the reference element, of the degree
//! given by [`crate::jacobian_degree`]. Written in the Bernstein basis of that degree, it lies
//! between its smallest and largest coefficient, and its vertex coefficients are its values
//! there. So, per element:
//! 1. compute det J's coefficients exactly from the Bézier control points of the element map
//!    (derivatives are coefficient differences, products have non-negative weights:
//!    [`crate::bezier_simplex`], [`crate::bezier_prism`], [`crate::bezier_map`]), with a
//!    bound on their rounding — no sampling, and no conversion matrix whose norm explodes
//!    with the degree (so every order to p = 10 and beyond is checked);
//! 2. if every coefficient is > 0, det J > 0 everywhere: **valid**;
//! 3. if a vertex coefficient (det J's value there) is < 0, the element is certainly
//!    **invalid**;
//! 4. otherwise split the region — triangles and tetrahedra by exact bisection of the
//!    longest edge, boxes and prisms into the 2^d children of a midpoint refinement by
//!    exact subdivision matrices — and repeat, up to `max_depth` levels (d bisections
//!    count as one level); what remains is **undecided**.
//!
//! Node sets that are not a tensor product on boxes (never hocurve's) fall back to sampling
//! det J at the Bernstein lattice and converting ([`crate::BernsteinSpace`]).
//!
//! The coefficients of the final regions also bound the extremes: min det J ≥ min of the
//! leaves' smallest coefficients and max det J ≤ max of their largest ones, which gives a
//! certified interval for the true scaled Jacobian min det J / max det J.
//!
//! Rounding: each coefficient carries a forward bound on its rounding (from the conversion of
//! the nodes to control points, amplified by that conversion's norm, through the
//! derivatives, products and subdivisions); it must exceed the bound to count as positive,
//! and the reported bounds are widened by it. Near-zero cases are thus undecided rather
//! than wrong. The bound relative to max det J on a smoothly curved element grows with the
//! order: ~1e-10 at p = 4 and ~1e-4 at p = 10 on prisms (see the tests), so at high order
//! elements with Ĩ below that come out undecided.

use std::collections::BTreeMap;
use std::sync::Arc;

use hocurve_mesh::HighOrderMesh;
use hocurve_nodes::{determinant, isoparametric_jacobian, NodeFamily, ReferenceElement, Shape};
use rayon::prelude::*;
use serde::Serialize;

use crate::bezier_map::TensorJacobian;
use crate::bezier_prism::PrismJacobian;
use crate::bezier_simplex::SimplexJacobian;
use crate::bound_refinement::{extremes, Region, SimplexBisection};
use crate::jacobian::{
    affine_determinant, check_cells, gather, min_max, scaled_ratio, JacobianSampler,
    JacobianWorkspace,
};
use crate::{BernsteinSpace, BernsteinSubdivision, QualityError};

/// Regions waiting (coefficients, depth, rounding bound), spare coefficient vectors and
/// scratch of [`JacobianBezier::check_subdivided`].
type SubdivisionScratch<'a> = (
    &'a mut Vec<(Vec<f64>, usize, f64)>,
    &'a mut Vec<Vec<f64>>,
    &'a mut Vec<f64>,
);

/// Coefficients per region that [`BezierOptions::max_regions`] counts in whole regions (the
/// det J of a p = 6 tetrahedron has 816, of a p = 8 prism 6 624).
const REGION_COEFFICIENTS: usize = 1000;

/// The verdict of the Bézier check on one element.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Validity {
    /// det J > 0 everywhere on the element (certified).
    Valid,
    /// det J < 0 somewhere (a point was found).
    Invalid,
    /// Neither could be shown within the subdivision depth (det J is close to 0 somewhere).
    Undecided,
}

/// Options of the Bézier validity check.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BezierOptions {
    /// Levels of subdivision before giving up (0: only the whole element).
    pub max_depth: usize,
    /// When every element is valid, narrow the certified bounds of the elements that hold
    /// the mesh's bound down ([`JacobianBezier::refine_bounds`]) until each certifies
    /// Ĩ ≥ this fraction of the smallest Ĩ sampled on any element — or, where an element's
    /// own values prove its Ĩ lower than that, this fraction of its own upper bound
    /// (0: no narrowing).
    pub tightness: f64,
    /// Regions one element may be split into while narrowing (regions of more than 1 000
    /// coefficients count in proportion to their size).
    pub max_regions: usize,
}

impl Default for BezierOptions {
    fn default() -> Self {
        BezierOptions {
            max_depth: 4,
            tightness: 0.95,
            max_regions: 1024,
        }
    }
}

/// Where [`JacobianBezier::refine_bounds`] stops narrowing an element's certified Ĩ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NarrowingGoal {
    /// A certified lower bound of Ĩ that is enough (the mesh's: a fraction of its smallest
    /// sampled Ĩ).
    pub target: f64,
    /// Enough when the element's own upper bound of Ĩ is below `target`: this fraction of
    /// that upper bound.
    pub relative: f64,
    /// Regions the element may be split into (regions of more than 1 000 coefficients
    /// count in proportion to their size).
    pub max_regions: usize,
}

/// The result of the Bézier check on one element.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct ValidityCheck {
    /// The verdict.
    pub validity: Validity,
    /// Certified lower bound of min det J over the element (smallest leaf coefficient).
    pub min_jacobian_lower_bound: f64,
    /// Certified upper bound of max det J (largest leaf coefficient).
    pub max_jacobian_upper_bound: f64,
    /// Lower bound of the true scaled Jacobian min det J / max det J.
    pub scaled_jacobian_lower_bound: f64,
    /// Upper bound of the true scaled Jacobian (from the sampled extremes).
    pub scaled_jacobian_upper_bound: f64,
    /// Number of (sub-)elements examined.
    pub regions: usize,
}

/// An affine map ξ = origin + matrix · η from a sub-element's reference coordinates η to
/// the element's ξ.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Affine {
    origin: [f64; 3],
    matrix: [[f64; 3]; 3],
}

impl Affine {
    const IDENTITY: Affine = Affine {
        origin: [0.0; 3],
        matrix: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
    };

    fn apply(&self, eta: [f64; 3]) -> [f64; 3] {
        let mut x = self.origin;
        for r in 0..3 {
            for c in 0..3 {
                x[r] += self.matrix[r][c] * eta[c];
            }
        }
        x
    }

    /// self ∘ inner.
    fn compose(&self, inner: &Affine) -> Affine {
        let mut matrix = [[0.0; 3]; 3];
        for r in 0..3 {
            for c in 0..3 {
                matrix[r][c] = (0..3).map(|k| self.matrix[r][k] * inner.matrix[k][c]).sum();
            }
        }
        Affine {
            origin: self.apply(inner.origin),
            matrix,
        }
    }

    /// The affine map sending the reference simplex's vertices to `w` (2 or 3 vertices
    /// beyond the first).
    fn simplex(w: &[[f64; 3]]) -> Affine {
        let mut a = Affine {
            origin: w[0],
            matrix: [[0.0; 3]; 3],
        };
        for k in 1..w.len() {
            for r in 0..3 {
                a.matrix[r][k - 1] = w[k][r] - w[0][r];
            }
        }
        if w.len() == 3 {
            a.matrix[2][2] = 1.0; // 2D: leave ζ alone (it is 0 on the triangle)
        }
        a
    }
}

fn mid(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [
        0.5 * (a[0] + b[0]),
        0.5 * (a[1] + b[1]),
        0.5 * (a[2] + b[2]),
    ]
}

/// The midpoint refinement of the reference triangle into 4 triangles, as vertex triples.
fn triangle_children() -> Vec<[[f64; 3]; 3]> {
    let v = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
    let (m01, m12, m02) = (mid(v[0], v[1]), mid(v[1], v[2]), mid(v[0], v[2]));
    vec![
        [v[0], m01, m02],
        [m01, v[1], m12],
        [m02, m12, v[2]],
        [m12, m02, m01],
    ]
}

/// Sub-elements of a reference element after one midpoint refinement.
fn children(shape: Shape) -> Vec<Affine> {
    let half = |o: [f64; 3]| Affine {
        origin: o,
        matrix: [[0.5, 0.0, 0.0], [0.0, 0.5, 0.0], [0.0, 0.0, 0.5]],
    };
    match shape {
        Shape::Line => vec![half([0.0; 3]), half([0.5, 0.0, 0.0])],
        Shape::Tri => triangle_children()
            .iter()
            .map(|w| Affine::simplex(w))
            .collect(),
        Shape::Quad => [[0.0, 0.0], [0.5, 0.0], [0.0, 0.5], [0.5, 0.5]]
            .iter()
            .map(|o| half([o[0], o[1], 0.0]))
            .collect(),
        Shape::Hex => (0..8)
            .map(|c| {
                let b = |k: usize| if c >> k & 1 == 1 { 0.5 } else { 0.0 };
                half([b(0), b(1), b(2)])
            })
            .collect(),
        Shape::Tet => {
            // Red refinement: 4 corner tetrahedra and the inner octahedron cut along the
            // diagonal m02–m13 into 4 (the cycle m01, m12, m23, m03 runs around it).
            let v = Shape::Tet.vertices();
            let m = |a: usize, b: usize| mid(v[a], v[b]);
            let (m01, m02, m03, m12, m13, m23) =
                (m(0, 1), m(0, 2), m(0, 3), m(1, 2), m(1, 3), m(2, 3));
            [
                [v[0], m01, m02, m03],
                [m01, v[1], m12, m13],
                [m02, m12, v[2], m23],
                [m03, m13, m23, v[3]],
                [m02, m13, m01, m12],
                [m02, m13, m12, m23],
                [m02, m13, m23, m03],
                [m02, m13, m03, m01],
            ]
            .iter()
            .map(|w| Affine::simplex(w))
            .collect()
        }
        Shape::Prism => {
            let mut out = Vec::with_capacity(8);
            for z in [0.0, 0.5] {
                for w in triangle_children() {
                    let mut a = Affine::simplex(&w);
                    a.origin[2] = z;
                    a.matrix[2][2] = 0.5;
                    out.push(a);
                }
            }
            out
        }
    }
}

/// det J in Bernstein form for one (shape, order, family): the lattice sampler of the whole
/// element, the Lagrange basis for sub-elements, the conversion, the refinement pattern.
#[derive(Debug, Clone)]
pub struct JacobianBezier {
    space: BernsteinSpace,
    /// Exact coefficient subdivision (quadrilaterals, hexahedra, prisms): children's
    /// coefficients from the parent's, instead of re-sampling det J through the Lagrange
    /// basis (O(n²) per lattice point: over a minute for a p = 6 hybrid mesh).
    subdivision: Option<BernsteinSubdivision>,
    /// Exact det J coefficients from the map's control points (quadrilaterals,
    /// hexahedra), whose margin does not carry the conversion's exponential norm.
    tensor: Option<TensorJacobian>,
    /// Exact det J coefficients of triangles and tetrahedra, tried first: most elements
    /// are certified by them alone, without sampling det J and converting.
    simplex: Option<SimplexJacobian>,
    /// Exact det J coefficients of prisms (the sampled conversion's norm explodes with p).
    prism: Option<PrismJacobian>,
    /// Exact bisection of triangle and tetrahedron coefficients, for narrowing bounds.
    bisection: Option<SimplexBisection>,
    /// det J sampled at the lattice points of the whole element (None for triangles and
    /// tetrahedra, which never sample).
    root: Option<JacobianSampler>,
    /// The shared reference element, whose basis samples sub-elements.
    element: Arc<ReferenceElement>,
    children: Vec<Affine>,
}

/// Scratch memory of [`JacobianBezier::check_with`]; reuse one per thread.
#[derive(Debug, Clone, Default)]
pub struct BezierWorkspace {
    jacobian: JacobianWorkspace,
    coords: Vec<[f64; 3]>,
    values: Vec<f64>,
    tmp: Vec<f64>,
    grad_scratch: Vec<[f64; 3]>,
    grads: Vec<[f64; 3]>,
    stack: Vec<(Affine, usize)>,
    /// Regions waiting (coefficients, depth, rounding bound) and spare coefficient vectors.
    coefficient_stack: Vec<(Vec<f64>, usize, f64)>,
    spare: Vec<Vec<f64>>,
}

impl JacobianBezier {
    /// Precomputes everything for order-`order` elements of `shape` with `family` nodes.
    pub fn new(shape: Shape, order: usize, family: NodeFamily) -> Result<Self, QualityError> {
        let simplex_shape = matches!(shape, Shape::Tri | Shape::Tet);
        let prism = PrismJacobian::new(shape, order, family)?;
        let tensor = TensorJacobian::new(shape, order, family)?;
        // Exact coefficients everywhere they exist: no lattice sampling (whose set-up alone,
        // the Lagrange gradients at (3p)³ points, took 12 s for p = 8 hexahedra).
        let exact = prism.is_some() || tensor.is_some();
        let space = if simplex_shape || exact {
            BernsteinSpace::lattice_only(shape, order)?
        } else {
            BernsteinSpace::for_jacobian(shape, order)?
        };
        let simplex = SimplexJacobian::new(shape, order, family, &space)?;
        let root = match simplex {
            Some(_) => None,
            None if exact => None,
            None if simplex_shape => {
                // Only p = 0 (no map) ends here: there is nothing to certify with.
                return Err(QualityError::UnsupportedBezierDegree {
                    shape,
                    order,
                    degree: 0,
                    max: 0,
                });
            }
            None => Some(JacobianSampler::at_points(
                shape,
                order,
                family,
                space.points(),
            )?),
        };
        let element = ReferenceElement::shared(shape, order, family)?;
        Ok(JacobianBezier {
            tensor,
            simplex,
            prism,
            subdivision: space.subdivision(),
            bisection: SimplexBisection::new(&space),
            space,
            root,
            element,
            children: children(shape),
        })
    }

    /// The Bernstein space of det J.
    pub fn space(&self) -> &BernsteinSpace {
        &self.space
    }

    /// The Bernstein coefficients of det J on the whole element with node coordinates
    /// `coords` (canonical local order); evaluate with [`BernsteinSpace::eval`].
    pub fn coefficients(&self, coords: &[[f64; 3]]) -> Vec<f64> {
        if let Some(simplex) = &self.simplex {
            return simplex.coefficients(coords).0;
        }
        if let Some(prism) = &self.prism {
            return prism.coefficients(coords).0;
        }
        if let Some(tensor) = &self.tensor {
            return tensor.coefficients(coords).0;
        }
        let Some(root) = &self.root else {
            return vec![f64::NAN; self.space.len()];
        };
        let mut workspace = JacobianWorkspace::default();
        let mut c = root.determinants_with(coords, &mut workspace).to_vec();
        self.space.values_to_coefficients(&mut c, &mut Vec::new());
        c
    }

    /// det J at the lattice points of the sub-element `map`, into `ws.values`.
    fn sample_region(
        &self,
        coords: &[[f64; 3]],
        map: &Affine,
        grad_scratch: &mut Vec<[f64; 3]>,
        grads: &mut Vec<[f64; 3]>,
        values: &mut Vec<f64>,
    ) {
        let dim = self.space.shape().dim();
        let n = self.element.len();
        grad_scratch.resize(n, [0.0; 3]);
        grads.resize(n, [0.0; 3]);
        values.clear();
        for &eta in self.space.points() {
            let xi = map.apply(eta);
            self.element.basis().eval_grad_with(xi, grad_scratch, grads);
            values.push(determinant(
                &isoparametric_jacobian(coords, grads, dim),
                dim,
            ));
        }
    }

    /// Runs the check on the element with node coordinates `coords`.
    pub fn check_with(
        &self,
        coords: &[[f64; 3]],
        options: &BezierOptions,
        ws: &mut BezierWorkspace,
    ) -> ValidityCheck {
        let BezierWorkspace {
            jacobian,
            values,
            tmp,
            grad_scratch,
            grads,
            stack,
            coefficient_stack,
            spare,
            ..
        } = ws;
        if let Some(simplex) = &self.simplex {
            return self.check_simplex(simplex, coords, options, coefficient_stack, spare, tmp);
        }
        let exact = match (&self.prism, &self.tensor) {
            (Some(prism), _) => Some(prism.coefficients(coords)),
            (None, Some(tensor)) => Some(tensor.coefficients(coords)),
            (None, None) => None,
        };
        if let (Some(root), Some(sub)) = (exact, &self.subdivision) {
            // Exact coefficients, no sampling: the values met are the vertex coefficients.
            return self.check_subdivided(
                sub,
                root,
                0.0,
                None,
                options,
                (coefficient_stack, spare, tmp),
            );
        }
        let Some(root) = &self.root else {
            return self.verdict(
                (false, true),
                (f64::NAN, f64::NAN),
                (f64::NAN, f64::NAN),
                0.0,
                0,
            );
        };
        let root = root.determinants_with(coords, jacobian);
        let (sample_min, sample_max) = min_max(root);
        let scale = root.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let value_margin = (32.0 + coords.len() as f64) * f64::EPSILON * scale;
        let coefficient_margin = value_margin * self.space.conversion_norm().max(1.0);
        if !scale.is_finite() || scale == 0.0 {
            // Non-finite coordinates or a collapsed element: nothing can be certified.
            let validity = if sample_min < 0.0 {
                Validity::Invalid
            } else {
                Validity::Undecided
            };
            return ValidityCheck {
                validity,
                min_jacobian_lower_bound: f64::NAN,
                max_jacobian_upper_bound: f64::NAN,
                scaled_jacobian_lower_bound: -1.0,
                scaled_jacobian_upper_bound: crate::scaled_ratio(sample_min, sample_max),
                regions: 1,
            };
        }

        let mut lower = f64::INFINITY;
        let mut upper = f64::NEG_INFINITY;
        let (mut sampled_min, mut sampled_max) = (sample_min, sample_max);
        let (mut negative, mut undecided) = (false, false);
        let mut regions = 0;
        if let Some(sub) = &self.subdivision {
            // Shapes without exact coefficients (nodes that are not a tensor product):
            // converted samples.
            let mut root_coefficients = spare.pop().unwrap_or_default();
            root_coefficients.clear();
            root_coefficients.extend_from_slice(root);
            self.space
                .values_to_coefficients(&mut root_coefficients, tmp);
            return self.check_subdivided(
                sub,
                (root_coefficients, coefficient_margin),
                value_margin,
                Some((sample_min, sample_max)),
                options,
                (coefficient_stack, spare, tmp),
            );
        }
        stack.clear();
        stack.push((Affine::IDENTITY, 0));
        while let Some((map, depth)) = stack.pop() {
            regions += 1;
            if depth == 0 {
                values.clear();
                values.extend_from_slice(root);
            } else {
                self.sample_region(coords, &map, grad_scratch, grads, values);
            }
            let (vmin, vmax) = min_max(values);
            sampled_min = sampled_min.min(vmin);
            sampled_max = sampled_max.max(vmax);
            self.space.values_to_coefficients(values, tmp);
            let (cmin, cmax) = min_max(values);
            let found_negative = vmin < -value_margin;
            negative |= found_negative;
            let certified = cmin > coefficient_margin;
            // Once an inversion is found the verdict is settled: stop refining and keep the
            // (looser) bounds of the current regions.
            if certified || negative || depth >= options.max_depth {
                undecided |= !certified && !found_negative;
                lower = lower.min(cmin);
                upper = upper.max(cmax);
                continue;
            }
            for child in &self.children {
                stack.push((map.compose(child), depth + 1));
            }
        }

        self.verdict(
            (negative, undecided),
            (lower, upper),
            (sampled_min, sampled_max),
            coefficient_margin,
            regions,
        )
    }

    /// The check by exact subdivision (quadrilaterals, hexahedra, prisms) from det J's
    /// coefficients on the whole element and their rounding bound: regions split into the
    /// children of a midpoint refinement while neither certified nor inverted, up to
    /// `max_depth` levels. `value_margin` is the rounding of sampled values and `sampled`
    /// their extremes; without samples (None) the vertex coefficients of every region,
    /// the root's included, are the values met.
    fn check_subdivided(
        &self,
        sub: &BernsteinSubdivision,
        (root, coefficient_margin): (Vec<f64>, f64),
        value_margin: f64,
        sampled: Option<(f64, f64)>,
        options: &BezierOptions,
        (stack, spare, tmp): SubdivisionScratch<'_>,
    ) -> ValidityCheck {
        let scale = root.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if sampled.is_none() {
            if let Some(check) = unusable(&root, sub.vertices(), scale, coefficient_margin) {
                return check;
            }
        }
        let (mut sampled_min, mut sampled_max) =
            sampled.unwrap_or((f64::INFINITY, f64::NEG_INFINITY));
        let include_root = sampled.is_none();
        let (mut lower, mut upper) = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut negative, mut undecided) = (false, false);
        let mut regions = 0;
        // Regions carry their coefficients and a bound on the rounding the subdivisions
        // added to them (rows are convex combinations: ≤ m ε max|c| per factor).
        let growth = (sub.factors() * sub.longest_factor()) as f64 * f64::EPSILON;
        stack.clear();
        stack.push((root, 0, 0.0));
        while let Some((c, depth, error)) = stack.pop() {
            regions += 1;
            let (cmin, cmax) = min_max(&c);
            // Vertex coefficients are det J at the region's vertices (to the margins).
            let found_negative = sub
                .vertices()
                .iter()
                .any(|&v| c[v] < -(value_margin + coefficient_margin + error));
            if depth > 0 || include_root {
                for &v in sub.vertices() {
                    sampled_min = sampled_min.min(c[v]);
                    sampled_max = sampled_max.max(c[v]);
                }
            }
            negative |= found_negative;
            let certified = cmin > coefficient_margin + error;
            if certified || negative || depth >= options.max_depth {
                undecided |= !certified && !found_negative;
                lower = lower.min(cmin - error);
                upper = upper.max(cmax + error);
                spare.push(c);
                continue;
            }
            let scale = c.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            for child in 0..sub.len() {
                let mut d = spare.pop().unwrap_or_default();
                sub.child(child, &c, &mut d, tmp);
                stack.push((d, depth + 1, error + growth * scale));
            }
            spare.push(c);
        }
        self.verdict(
            (negative, undecided),
            (lower, upper),
            (sampled_min, sampled_max),
            coefficient_margin,
            regions,
        )
    }

    /// The check of a triangle or tetrahedron: det J's exact coefficients on the element
    /// ([`crate::bezier_simplex`]), then, while neither certified nor inverted, exact
    /// bisections of the regions' longest edges (de Casteljau, no re-sampling), up to
    /// `dim × max_depth` bisections deep — as fine as `max_depth` midpoint refinements.
    /// Vertex coefficients are det J's values at the regions' vertices: one below −margin
    /// shows an inversion.
    fn check_simplex(
        &self,
        simplex: &SimplexJacobian,
        coords: &[[f64; 3]],
        options: &BezierOptions,
        stack: &mut Vec<(Vec<f64>, usize, f64)>,
        spare: &mut Vec<Vec<f64>>,
        line: &mut Vec<f64>,
    ) -> ValidityCheck {
        let (root, margin) = simplex.coefficients(coords);
        let vertices = simplex.vertices();
        let scale = root.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if let Some(check) = unusable(&root, vertices, scale, margin) {
            return check;
        }
        let Some(bisection) = &self.bisection else {
            return self.verdict(
                (false, true),
                (f64::NAN, f64::NAN),
                (f64::NAN, f64::NAN),
                0.0,
                1,
            );
        };
        let corners = bisection.corners();
        let max_splits = options.max_depth * (corners - 1);
        let (mut lower, mut upper) = (f64::INFINITY, f64::NEG_INFINITY);
        let mut sampled = (f64::INFINITY, f64::NEG_INFINITY);
        let (mut negative, mut undecided) = (false, false);
        let mut regions = 0;
        let mut reference = [[0.0; 3]; 4];
        for (c, v) in reference
            .iter_mut()
            .zip(self.space.shape().vertices().iter())
        {
            *c = *v;
        }
        // Regions carry their reference corners (to split the longest edge) through a
        // parallel stack of corner sets.
        let mut shapes: Vec<[[f64; 3]; 4]> = vec![reference];
        stack.clear();
        stack.push((root, 0, 0.0));
        while let (Some((c, depth, error)), Some(region_corners)) = (stack.pop(), shapes.pop()) {
            regions += 1;
            let (cmin, cmax) = min_max(&c);
            for &v in vertices {
                sampled.0 = sampled.0.min(c[v]);
                sampled.1 = sampled.1.max(c[v]);
            }
            let found_negative = vertices.iter().any(|&v| c[v] < -(margin + error));
            negative |= found_negative;
            let certified = cmin > margin + error;
            if certified || negative || depth >= max_splits {
                undecided |= !certified && !found_negative;
                lower = lower.min(cmin - error);
                upper = upper.max(cmax + error);
                spare.push(c);
                continue;
            }
            let region = Region {
                c,
                min: cmin,
                max: cmax,
                error,
                corners: region_corners,
            };
            let (i, j) = region.longest_edge(corners);
            let scale = region.c.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            let child_error = error + bisection.degree() as f64 * f64::EPSILON * scale;
            let (mut a, mut b) = (
                spare.pop().unwrap_or_default(),
                spare.pop().unwrap_or_default(),
            );
            bisection.bisect(&region.c, (i, j), &mut a, &mut b, line);
            let m = mid(region.corners[i], region.corners[j]);
            let (mut ca, mut cb) = (region.corners, region.corners);
            ca[j] = m;
            cb[i] = m;
            stack.push((a, depth + 1, child_error));
            shapes.push(ca);
            stack.push((b, depth + 1, child_error));
            shapes.push(cb);
            spare.push(region.c);
        }
        self.verdict(
            (negative, undecided),
            (lower, upper),
            sampled,
            margin,
            regions,
        )
    }

    /// Narrows the certified interval of Ĩ of a valid element (`check`, from
    /// [`Self::check_with`]) by best-first subdivision (see [`crate::bound_refinement`]):
    /// splits the region holding the smallest coefficient — or the largest, when that end of
    /// the interval is relatively further from the values found — until the certified
    /// lower bound of Ĩ reaches `goal.target`; or, once the element's own upper bound (the
    /// check's, lowered by every value of det J met) shows the target out of reach,
    /// `goal.relative` times that upper bound; or `goal.max_regions` regions are in use.
    /// Returns `check` with the narrower bounds (never wider ones); other verdicts are
    /// returned as they are.
    pub fn refine_bounds(
        &self,
        coords: &[[f64; 3]],
        check: &ValidityCheck,
        goal: &NarrowingGoal,
        ws: &mut BezierWorkspace,
    ) -> ValidityCheck {
        let NarrowingGoal {
            target,
            relative,
            max_regions,
        } = *goal;
        // Past the target; or the target is out of reach (the element's Ĩ is below it) and
        // the bound is within `relative` of the element's own upper bound.
        let reached = |c: &ValidityCheck| {
            let (lower, upper) = (c.scaled_jacobian_lower_bound, c.scaled_jacobian_upper_bound);
            lower >= target || (upper < target && lower >= relative * upper)
        };
        if check.validity != Validity::Valid || reached(check) {
            return *check;
        }
        let Some((root, margin)) = self.root_coefficients(coords, ws) else {
            return *check;
        };
        // The budget counts regions of at most REGION_COEFFICIENTS coefficients; larger
        // ones (prisms and hexahedra of high order: 6 624 at p = 8) count in proportion,
        // so that narrowing costs about the same per element at any order.
        let budget = if self.space.len() > REGION_COEFFICIENTS {
            (max_regions * REGION_COEFFICIENTS / self.space.len()).max(16)
        } else {
            max_regions
        };
        let reference = self.space.shape().vertices();
        let mut corners = [[0.0; 3]; 4];
        for (c, v) in corners.iter_mut().zip(reference.iter()) {
            *c = *v;
        }
        let vertex_positions: &[usize] = match (&self.bisection, &self.subdivision) {
            (Some(b), _) => b.vertices(),
            (None, Some(s)) => s.vertices(),
            (None, None) => return *check,
        };
        // det J's extremes among the values met (vertex coefficients of the regions).
        let mut sampled = (f64::INFINITY, f64::NEG_INFINITY);
        let note_values = |sampled: &mut (f64, f64), c: &[f64]| {
            for &v in vertex_positions {
                sampled.0 = sampled.0.min(c[v]);
                sampled.1 = sampled.1.max(c[v]);
            }
        };
        note_values(&mut sampled, &root);
        let mut regions = vec![Region::new(root, 0.0, corners)];
        let children = match (&self.bisection, &self.subdivision) {
            (Some(_), _) => 2,
            (None, Some(s)) => s.len(),
            (None, None) => return *check,
        };
        let mut line = Vec::new();
        let mut best = *check;
        loop {
            let ((lower, low_at), (upper, high_at)) = extremes(&regions);
            let (lower, upper) = (lower - margin, upper + margin);
            if !(lower.is_finite() && upper.is_finite()) {
                break;
            }
            if lower > 0.0 && lower / upper > best.scaled_jacobian_lower_bound {
                best.min_jacobian_lower_bound = best.min_jacobian_lower_bound.max(lower);
                best.max_jacobian_upper_bound = best.max_jacobian_upper_bound.min(upper);
                best.scaled_jacobian_lower_bound = lower / upper;
            }
            if sampled.0 > 0.0 && sampled.1 > 0.0 {
                best.scaled_jacobian_upper_bound =
                    best.scaled_jacobian_upper_bound.min(sampled.0 / sampled.1);
            }
            if reached(&best) || regions.len() + children - 1 > budget {
                break;
            }
            // Split where the interval is relatively loosest (the smallest coefficient
            // while it is not yet positive: the valid element's check got there by splitting).
            let at = if lower <= 0.0 || sampled.0 / lower >= upper / sampled.1 {
                low_at
            } else {
                high_at
            };
            let region = regions.swap_remove(at);
            let scale = region.c.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
            match (&self.bisection, &self.subdivision) {
                (Some(bisection), _) => {
                    let n = bisection.corners();
                    let (i, j) = region.longest_edge(n);
                    let error = region.error + bisection.degree() as f64 * f64::EPSILON * scale;
                    let (mut a, mut b) = (Vec::new(), Vec::new());
                    bisection.bisect(&region.c, (i, j), &mut a, &mut b, &mut line);
                    let m = mid(region.corners[i], region.corners[j]);
                    let (mut ca, mut cb) = (region.corners, region.corners);
                    ca[j] = m;
                    cb[i] = m;
                    note_values(&mut sampled, &a);
                    note_values(&mut sampled, &b);
                    regions.push(Region::new(a, error, ca));
                    regions.push(Region::new(b, error, cb));
                }
                (None, Some(sub)) => {
                    let growth = (sub.factors() * sub.longest_factor()) as f64 * f64::EPSILON;
                    for child in 0..sub.len() {
                        let mut d = Vec::new();
                        sub.child(child, &region.c, &mut d, &mut ws.tmp);
                        note_values(&mut sampled, &d);
                        regions.push(Region::new(d, region.error + growth * scale, corners));
                    }
                }
                (None, None) => break,
            }
        }
        if sampled.0 > 0.0 && sampled.1 > 0.0 {
            best.scaled_jacobian_upper_bound =
                best.scaled_jacobian_upper_bound.min(sampled.0 / sampled.1);
        }
        best.regions += regions.len();
        best
    }

    /// det J's Bernstein coefficients on the whole element and a bound on their rounding:
    /// exact from the map's control points where the shape allows, else from samples.
    fn root_coefficients(
        &self,
        coords: &[[f64; 3]],
        ws: &mut BezierWorkspace,
    ) -> Option<(Vec<f64>, f64)> {
        if let Some(simplex) = &self.simplex {
            return Some(simplex.coefficients(coords));
        }
        if let Some(prism) = &self.prism {
            return Some(prism.coefficients(coords));
        }
        if let Some(tensor) = &self.tensor {
            return Some(tensor.coefficients(coords));
        }
        let root = self
            .root
            .as_ref()?
            .determinants_with(coords, &mut ws.jacobian);
        let scale = root.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        if !scale.is_finite() || scale == 0.0 {
            return None;
        }
        let value_margin = (32.0 + coords.len() as f64) * f64::EPSILON * scale;
        let mut c = root.to_vec();
        self.space.values_to_coefficients(&mut c, &mut ws.tmp);
        Some((c, value_margin * self.space.conversion_norm().max(1.0)))
    }

    /// The check's result from what the regions found: an inversion, undecided leaves, the
    /// leaves' coefficient range, the sampled extremes.
    fn verdict(
        &self,
        (negative, undecided): (bool, bool),
        (lower, upper): (f64, f64),
        (sampled_min, sampled_max): (f64, f64),
        coefficient_margin: f64,
        regions: usize,
    ) -> ValidityCheck {
        let validity = if negative {
            Validity::Invalid
        } else if undecided {
            Validity::Undecided
        } else {
            Validity::Valid
        };
        // Coefficient bounds hold up to the conversion's rounding: widen by the margin.
        let lower = lower - coefficient_margin;
        let upper = upper + coefficient_margin;
        // min/max ≥ lower/upper when lower ≥ 0; ≥ lower/(a lower bound of max) otherwise.
        let scaled_lower = if lower >= 0.0 {
            lower / upper
        } else if sampled_max > 0.0 {
            lower / sampled_max
        } else {
            -1.0
        };
        let scaled_upper = if sampled_min >= 0.0 {
            sampled_min / sampled_max
        } else {
            sampled_min / upper
        };
        ValidityCheck {
            validity,
            min_jacobian_lower_bound: lower,
            max_jacobian_upper_bound: upper,
            scaled_jacobian_lower_bound: scaled_lower,
            scaled_jacobian_upper_bound: scaled_upper,
            regions,
        }
    }
}

/// The check of an element whose exact coefficients `c` (largest magnitude `scale`, rounding
/// bound `margin`) certify nothing — non-finite coordinates or a collapsed element —:
/// invalid if a vertex value (at `vertices`) is negative beyond the margin, else undecided.
/// None when the coefficients are usable.
fn unusable(c: &[f64], vertices: &[usize], scale: f64, margin: f64) -> Option<ValidityCheck> {
    if scale.is_finite() && margin.is_finite() && scale != 0.0 {
        return None;
    }
    let corner_min = vertices.iter().map(|&v| c[v]).fold(f64::INFINITY, f64::min);
    Some(ValidityCheck {
        validity: if corner_min < -margin {
            Validity::Invalid
        } else {
            Validity::Undecided
        },
        min_jacobian_lower_bound: f64::NAN,
        max_jacobian_upper_bound: f64::NAN,
        scaled_jacobian_lower_bound: -1.0,
        scaled_jacobian_upper_bound: f64::NAN,
        regions: 1,
    })
}

/// The Bézier validity check of every cell (Vec indexed like `mesh.cells`), in parallel and
/// deterministic.
pub fn check_validity(
    mesh: &HighOrderMesh,
    options: &BezierOptions,
) -> Result<Vec<ValidityCheck>, QualityError> {
    check_validity_where(mesh, options, None, None)
}

/// [`check_validity`], with the cells flagged in `affine` (simplices whose nodes are the
/// straight-sided ones) decided by the sign of their constant det J, and each cell's
/// scaled Jacobian sampled elsewhere (`sampled`, e.g. at the degree-2p points: min/max
/// over points, an upper bound of the true Ĩ of a valid cell) lowering its upper bound.
pub(crate) fn check_validity_where(
    mesh: &HighOrderMesh,
    options: &BezierOptions,
    affine: Option<&[bool]>,
    sampled: Option<&[f64]>,
) -> Result<Vec<ValidityCheck>, QualityError> {
    let shapes = check_cells(mesh)?;
    let checkers: BTreeMap<Shape, JacobianBezier> = shapes
        .iter()
        .map(|&s| Ok((s, JacobianBezier::new(s, mesh.order, mesh.family)?)))
        .collect::<Result<_, QualityError>>()?;
    // check_cells put every cell's shape in `checkers`.
    let mut checks: Vec<ValidityCheck> = mesh
        .cells
        .par_iter()
        .enumerate()
        .map_init(BezierWorkspace::default, |ws, (c, cell)| {
            if let Some(det) = affine_determinant(mesh, cell, affine, c) {
                let ratio = scaled_ratio(det, det);
                return ValidityCheck {
                    validity: if det > 0.0 {
                        Validity::Valid
                    } else {
                        Validity::Invalid
                    },
                    min_jacobian_lower_bound: det,
                    max_jacobian_upper_bound: det,
                    scaled_jacobian_lower_bound: ratio,
                    scaled_jacobian_upper_bound: ratio,
                    regions: 1,
                };
            }
            let checker = &checkers[&cell.kind];
            let mut coords = std::mem::take(&mut ws.coords);
            gather(mesh, cell, &mut coords);
            let check = checker.check_with(&coords, options, ws);
            ws.coords = coords;
            check
        })
        .collect();
    if let Some(sampled) = sampled {
        for (check, &s) in checks.iter_mut().zip(sampled) {
            // Only a valid cell's sampled ratio bounds its Ĩ from above (both extremes > 0).
            if check.validity == Validity::Valid && s > 0.0 && s.is_finite() {
                check.scaled_jacobian_upper_bound = check.scaled_jacobian_upper_bound.min(s);
            }
        }
    }
    Ok(narrow_bounds(mesh, &checkers, checks, options))
}

/// The checks with the certified bounds of the elements below the target of
/// [`BezierOptions::tightness`] narrowed, when every element is valid: the mesh's certified
/// min Ĩ then sits within that fraction of the smallest Ĩ known (sampled, or proven by an
/// element's values), or as close as the region budget allows.
fn narrow_bounds(
    mesh: &HighOrderMesh,
    checkers: &BTreeMap<Shape, JacobianBezier>,
    mut checks: Vec<ValidityCheck>,
    options: &BezierOptions,
) -> Vec<ValidityCheck> {
    if options.tightness <= 0.0 || checks.iter().any(|c| c.validity != Validity::Valid) {
        return checks;
    }
    let sampled = checks
        .iter()
        .map(|c| c.scaled_jacobian_upper_bound)
        .fold(f64::INFINITY, f64::min);
    let target = options.tightness * sampled;
    if target.is_nan() || target <= 0.0 {
        return checks;
    }
    let goal = NarrowingGoal {
        target,
        relative: options.tightness,
        max_regions: options.max_regions,
    };
    checks
        .par_iter_mut()
        .enumerate()
        .filter(|(_, check)| check.scaled_jacobian_lower_bound < target)
        .for_each_init(BezierWorkspace::default, |ws, (c, check)| {
            let cell = &mesh.cells[c];
            let mut coords = std::mem::take(&mut ws.coords);
            gather(mesh, cell, &mut coords);
            *check = checkers[&cell.kind].refine_bounds(&coords, check, &goal, ws);
            ws.coords = coords;
        });
    checks
}

#[cfg(test)]
#[path = "tests/validity.rs"]
mod tests;
