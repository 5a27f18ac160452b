use super::*;
use crate::sparse::from_rows;

struct Identity;
impl Preconditioner for Identity {
    fn apply(&mut self, r: &[f64], z: &mut [f64]) {
        z.copy_from_slice(r);
    }
}

#[test]
fn cg_solves_the_1d_laplacian_in_n_steps() {
    // [2 −1; −1 2 −1; …] x = e₀ + e_{n−1} has the solution x = 1.
    let n: usize = 40;
    let rows = (0..n)
        .map(|r| {
            (r.saturating_sub(1)..(r + 2).min(n))
                .map(|c| (c as u32, if c == r { 2.0 } else { -1.0 }))
                .collect()
        })
        .collect();
    let a = from_rows(n, rows);
    let mut b = vec![0.0; n];
    b[0] = 1.0;
    b[n - 1] = 1.0;
    let mut x = vec![0.0; n];
    let iterations = pcg(&a, &b, &mut x, &mut Identity, 1e-12, 1000);
    // Exact arithmetic needs at most n/2 steps here (symmetric right-hand side).
    assert!(iterations <= n / 2 + 1, "{iterations}");
    assert!(x.iter().all(|v| (v - 1.0).abs() < 1e-10), "{x:?}");
}
