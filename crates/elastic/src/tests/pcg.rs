use super::*;
use crate::sparse::from_rows;

struct Identity;
impl Preconditioner for Identity {
    fn apply(&mut self, r: &[f64], z: &mut [f64]) {
        z.copy_from_slice(r);
    }
}

/// The n × n tridiagonal matrix [d −1; −1 d −1; …].
fn tridiagonal(n: usize, d: f64) -> StiffnessMatrix {
    let rows = (0..n)
        .map(|r| {
            (r.saturating_sub(1)..(r + 2).min(n))
                .map(|c| (c as u32, if c == r { d } else { -1.0 }))
                .collect()
        })
        .collect();
    from_rows(n, rows)
}

#[test]
fn cg_solves_the_1d_laplacian_in_n_steps() {
    // [2 −1; −1 2 −1; …] x = e₀ + e_{n−1} has the solution x = 1.
    let n: usize = 40;
    let a = tridiagonal(n, 2.0);
    let mut b = vec![0.0; n];
    b[0] = 1.0;
    b[n - 1] = 1.0;
    let mut x = vec![0.0; n];
    let iterations = pcg(&a, &b, &mut x, &mut Identity, 1e-12, 1000);
    // Exact arithmetic needs at most n/2 steps here (symmetric right-hand side).
    assert!(iterations <= n / 2 + 1, "{iterations}");
    assert!(x.iter().all(|v| (v - 1.0).abs() < 1e-10), "{x:?}");
}

/// Counts its applications.
struct CountingIdentity(usize);
impl Preconditioner for CountingIdentity {
    fn apply(&mut self, r: &[f64], z: &mut [f64]) {
        self.0 += 1;
        z.copy_from_slice(r);
    }
}

#[test]
fn the_error_estimate_stops_within_its_bound_and_skips_the_last_preconditioning() {
    // [4 −1; −1 4 −1; …] (condition number < 3): CG contracts the error steadily, by about
    // 0.27 per iteration, so the estimate's geometric tail is close to the truth.
    let n: usize = 200;
    let a = tridiagonal(n, 4.0);
    let b: Vec<f64> = (0..n).map(|i| ((i * 7919) % 101) as f64 / 101.0).collect();
    let mut exact = vec![0.0; n];
    pcg(&a, &b, &mut exact, &mut Identity, 1e-15, 1000);
    let mut skipped = 0;
    // Bounds from 1e-4 down, 4 per decade (7 to 16 iterations). Above, the stop comes by
    // the third iteration, before ρ settles: bound 5.6e-3 left an error of 9.8e-3.
    for bound in (16..40).map(|k| 10f64.powf(-k as f64 / 4.0)) {
        let mut x = vec![0.0; n];
        let mut counting = CountingIdentity(0);
        let outcome = pcg_with_progress(
            &a,
            &b,
            &mut x,
            &mut counting,
            1e-15,
            Some(bound),
            1000,
            &mut |_, _| {},
        );
        assert!(outcome.by_error_estimate, "{bound}: {outcome:?}");
        let error = x
            .iter()
            .zip(&exact)
            .fold(0.0f64, |m, (u, v)| m.max((u - v).abs()));
        assert!(error <= bound, "{bound:e}: error {error:e}");
        // One application before the first iteration and one per iteration, but for the
        // last when the contraction of the iterations before already bounds its tail.
        assert!(
            counting.0 == outcome.iterations || counting.0 == outcome.iterations + 1,
            "{bound}: {outcome:?}, {} applications",
            counting.0
        );
        skipped += usize::from(counting.0 == outcome.iterations);
    }
    assert!(skipped > 0);
}
