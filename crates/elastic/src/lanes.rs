//! One vector register of a cell action's sums: a few numbers side by side, multiplied and
//! added lane by lane. The sum-factorised kernels ([`crate::extruded_factors`]) and the
//! stresses at the quadrature points (`matrix_free::stress_modes`) are written on these
//! rather than on arrays because LLVM's vectoriser, left to itself, shuffled their
//! f32 sums through blends and stack spills (the f32 gradients ran no faster than the f64
//! ones). A product and a sum are always two operations, never one fused multiply-add, so
//! [`Portable`] (plain arrays, any CPU) and the AVX registers give the same bits.

use crate::matrix_free::CellReal;

/// `WIDTH` numbers of type `Real` side by side.
pub(crate) trait Lanes: Copy {
    type Real: CellReal;
    /// The register of half as many lanes (itself at one lane): the sums' last block when
    /// no more than half of a whole one would be used.
    type Half: Lanes<Real = Self::Real>;
    const WIDTH: usize;
    /// Every lane 0.
    fn zero() -> Self;
    /// Every lane `v`.
    fn splat(v: Self::Real) -> Self;
    /// `from[..WIDTH]`.
    fn load(from: &[Self::Real]) -> Self;
    /// Into `to[..WIDTH]`.
    fn store(self, to: &mut [Self::Real]);
    /// Lane by lane.
    fn mul(self, other: Self) -> Self;
    fn add(self, other: Self) -> Self;
    /// self + a b, lane by lane: the product rounded, then the sum.
    #[inline(always)]
    fn plus_product(self, a: Self, b: Self) -> Self {
        self.add(a.mul(b))
    }
    /// The first `len` lanes into `to[..len]` (`len` ≤ WIDTH ≤ 8).
    #[inline(always)]
    fn store_first(self, to: &mut [Self::Real], len: usize) {
        const { assert!(Self::WIDTH <= 8, "store_first's buffer holds 8 lanes") };
        let mut all = [Self::Real::default(); 8];
        self.store(&mut all);
        to[..len].copy_from_slice(&all[..len]);
    }
}

/// B lanes as an array: what any CPU runs.
#[derive(Clone, Copy)]
pub(crate) struct Portable<T, const B: usize>([T; B]);

/// [`Lanes`] for [`Portable`] of each width the kernels use, its half the next one down.
macro_rules! portable_lanes {
    ($($b:literal => $half:literal),*) => {$(
        impl<T: CellReal> Lanes for Portable<T, $b> {
            type Real = T;
            type Half = Portable<T, $half>;
            const WIDTH: usize = $b;
            #[inline(always)]
            fn zero() -> Self {
                Portable([T::default(); $b])
            }
            #[inline(always)]
            fn splat(v: T) -> Self {
                Portable([v; $b])
            }
            #[inline(always)]
            fn load(from: &[T]) -> Self {
                let mut lanes = [T::default(); $b];
                lanes.copy_from_slice(&from[..$b]);
                Portable(lanes)
            }
            #[inline(always)]
            fn store(self, to: &mut [T]) {
                to[..$b].copy_from_slice(&self.0);
            }
            #[inline(always)]
            fn mul(self, other: Self) -> Self {
                let mut lanes = self.0;
                for (a, b) in lanes.iter_mut().zip(other.0) {
                    *a = *a * b;
                }
                Portable(lanes)
            }
            #[inline(always)]
            fn add(self, other: Self) -> Self {
                let mut lanes = self.0;
                for (a, b) in lanes.iter_mut().zip(other.0) {
                    *a += b;
                }
                Portable(lanes)
            }
        }
    )*};
}

portable_lanes!(8 => 4, 4 => 2, 2 => 1, 1 => 1);

#[cfg(target_arch = "x86_64")]
pub(crate) use avx::{Avx2Double, Avx2Single};

/// The AVX registers. Values of these types are made only inside
/// `MatrixFreeStiffness::cell_action_avx2` (and the tests, after the same check), which
/// runs only where the CPU reports AVX2: that is what makes the intrinsics' calls sound.
#[cfg(target_arch = "x86_64")]
mod avx {
    use std::arch::x86_64::*;

    use super::Lanes;

    /// Four f64 in one AVX register.
    #[derive(Clone, Copy)]
    pub(crate) struct Avx2Double(__m256d);

    /// Eight f32 in one AVX register.
    #[derive(Clone, Copy)]
    pub(crate) struct Avx2Single(__m256);

    /// Two f64, four f32 in one SSE register: the halves of the above.
    #[derive(Clone, Copy)]
    pub(crate) struct SseDouble(__m128d);
    #[derive(Clone, Copy)]
    pub(crate) struct SseSingle(__m128);

    // SAFETY (every block below): the CPU has AVX2, hence AVX (see the module
    // documentation); loads and stores check their slice's length first.
    impl Lanes for Avx2Double {
        type Real = f64;
        type Half = SseDouble;
        const WIDTH: usize = 4;
        #[inline(always)]
        fn zero() -> Self {
            Avx2Double(unsafe { _mm256_setzero_pd() })
        }
        #[inline(always)]
        fn splat(v: f64) -> Self {
            Avx2Double(unsafe { _mm256_set1_pd(v) })
        }
        #[inline(always)]
        fn load(from: &[f64]) -> Self {
            let from = &from[..4];
            Avx2Double(unsafe { _mm256_loadu_pd(from.as_ptr()) })
        }
        #[inline(always)]
        fn store(self, to: &mut [f64]) {
            let to = &mut to[..4];
            unsafe { _mm256_storeu_pd(to.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn mul(self, other: Self) -> Self {
            Avx2Double(unsafe { _mm256_mul_pd(self.0, other.0) })
        }
        #[inline(always)]
        fn add(self, other: Self) -> Self {
            Avx2Double(unsafe { _mm256_add_pd(self.0, other.0) })
        }
    }

    impl Lanes for Avx2Single {
        type Real = f32;
        type Half = SseSingle;
        const WIDTH: usize = 8;
        #[inline(always)]
        fn zero() -> Self {
            Avx2Single(unsafe { _mm256_setzero_ps() })
        }
        #[inline(always)]
        fn splat(v: f32) -> Self {
            Avx2Single(unsafe { _mm256_set1_ps(v) })
        }
        #[inline(always)]
        fn load(from: &[f32]) -> Self {
            let from = &from[..8];
            Avx2Single(unsafe { _mm256_loadu_ps(from.as_ptr()) })
        }
        #[inline(always)]
        fn store(self, to: &mut [f32]) {
            let to = &mut to[..8];
            unsafe { _mm256_storeu_ps(to.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn mul(self, other: Self) -> Self {
            Avx2Single(unsafe { _mm256_mul_ps(self.0, other.0) })
        }
        #[inline(always)]
        fn add(self, other: Self) -> Self {
            Avx2Single(unsafe { _mm256_add_ps(self.0, other.0) })
        }
    }

    impl Lanes for SseDouble {
        type Real = f64;
        type Half = crate::lanes::Portable<f64, 1>;
        const WIDTH: usize = 2;
        #[inline(always)]
        fn zero() -> Self {
            SseDouble(unsafe { _mm_setzero_pd() })
        }
        #[inline(always)]
        fn splat(v: f64) -> Self {
            SseDouble(unsafe { _mm_set1_pd(v) })
        }
        #[inline(always)]
        fn load(from: &[f64]) -> Self {
            let from = &from[..2];
            SseDouble(unsafe { _mm_loadu_pd(from.as_ptr()) })
        }
        #[inline(always)]
        fn store(self, to: &mut [f64]) {
            let to = &mut to[..2];
            unsafe { _mm_storeu_pd(to.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn mul(self, other: Self) -> Self {
            SseDouble(unsafe { _mm_mul_pd(self.0, other.0) })
        }
        #[inline(always)]
        fn add(self, other: Self) -> Self {
            SseDouble(unsafe { _mm_add_pd(self.0, other.0) })
        }
    }

    impl Lanes for SseSingle {
        type Real = f32;
        type Half = crate::lanes::Portable<f32, 2>;
        const WIDTH: usize = 4;
        #[inline(always)]
        fn zero() -> Self {
            SseSingle(unsafe { _mm_setzero_ps() })
        }
        #[inline(always)]
        fn splat(v: f32) -> Self {
            SseSingle(unsafe { _mm_set1_ps(v) })
        }
        #[inline(always)]
        fn load(from: &[f32]) -> Self {
            let from = &from[..4];
            SseSingle(unsafe { _mm_loadu_ps(from.as_ptr()) })
        }
        #[inline(always)]
        fn store(self, to: &mut [f32]) {
            let to = &mut to[..4];
            unsafe { _mm_storeu_ps(to.as_mut_ptr(), self.0) }
        }
        #[inline(always)]
        fn mul(self, other: Self) -> Self {
            SseSingle(unsafe { _mm_mul_ps(self.0, other.0) })
        }
        #[inline(always)]
        fn add(self, other: Self) -> Self {
            SseSingle(unsafe { _mm_add_ps(self.0, other.0) })
        }
    }
}
