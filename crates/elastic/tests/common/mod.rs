//! Structured test meshes: squares and cubes split into every element type, with interior
//! vertices moved by a deterministic pseudo-random amount so that cells are general.
#![allow(dead_code)]

use hocurve_mesh::{Element, ElementType, HighOrderMesh, LinearMesh};
use hocurve_nodes::NodeFamily;

/// How a cube of the structured grid is filled.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fill {
    Tet,
    Hex,
    Prism,
    /// Hexahedra where x < 1/2, prisms elsewhere.
    HexPrism,
}

/// A deterministic value in [−1, 1].
fn jitter(i: usize, j: usize, k: usize, axis: usize) -> f64 {
    let t = (i as f64) * 12.9898 + (j as f64) * 78.233 + (k as f64) * 37.719 + axis as f64 * 4.1;
    (t.sin() * 43758.5453).fract() * 2.0 - 1.0
}

fn signed_volume(v: &[[f64; 3]], ids: &[u32]) -> f64 {
    let p = |k: usize| v[ids[k] as usize];
    let (a, b, c, d) = (p(0), p(1), p(2), p(3));
    let e = |x: [f64; 3], y: [f64; 3]| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let (u, w, z) = (e(b, a), e(c, a), e(d, a));
    u[0] * (w[1] * z[2] - w[2] * z[1]) - u[1] * (w[0] * z[2] - w[2] * z[0])
        + u[2] * (w[0] * z[1] - w[1] * z[0])
}

/// The unit square with n × n quads or 2n² triangles; interior vertices moved by up to
/// `perturb` · h.
pub fn square(n: usize, kind: ElementType, perturb: f64) -> LinearMesh {
    let h = 1.0 / n as f64;
    let id = |i: usize, j: usize| (i + (n + 1) * j) as u32;
    let mut vertices = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let mut x = [i as f64 * h, j as f64 * h, 0.0];
            if i > 0 && i < n && j > 0 && j < n {
                x[0] += perturb * h * jitter(i, j, 0, 0);
                x[1] += perturb * h * jitter(i, j, 0, 1);
            }
            vertices.push(x);
        }
    }
    let mut cells = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            let lists = match kind {
                ElementType::Quad => vec![vec![a, b, c, d]],
                _ => vec![vec![a, b, c], vec![a, c, d]],
            };
            for vertices in lists {
                cells.push(Element {
                    kind,
                    vertices,
                    entity: 1,
                });
            }
        }
    }
    LinearMesh {
        dim: 2,
        vertices,
        cells,
        ..Default::default()
    }
}

/// The unit cube with n³ sub-cubes filled as asked.
pub fn cube(n: usize, fill: Fill, perturb: f64) -> LinearMesh {
    let h = 1.0 / n as f64;
    let id = |i: usize, j: usize, k: usize| (i + (n + 1) * (j + (n + 1) * k)) as u32;
    let mut vertices = Vec::new();
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                let mut x = [i as f64 * h, j as f64 * h, k as f64 * h];
                let inside = [i, j, k].iter().all(|&t| t > 0 && t < n);
                if inside {
                    for d in 0..3 {
                        x[d] += perturb * h * jitter(i, j, k, d);
                    }
                }
                vertices.push(x);
            }
        }
    }
    let mut cells = Vec::new();
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                // Local cube vertex with bits (x, y, z).
                let v = |bits: usize| id(i + (bits & 1), j + ((bits >> 1) & 1), k + (bits >> 2));
                let hex = vec![v(0), v(1), v(3), v(2), v(4), v(5), v(7), v(6)];
                let prisms = || {
                    vec![
                        vec![v(0), v(1), v(3), v(4), v(5), v(7)],
                        vec![v(0), v(3), v(2), v(4), v(7), v(6)],
                    ]
                };
                let use_hex = match fill {
                    Fill::Hex => true,
                    Fill::HexPrism => 2 * i < n,
                    _ => false,
                };
                if fill == Fill::Tet {
                    for (a, b) in [(1, 2), (2, 1), (1, 4), (4, 1), (2, 4), (4, 2)] {
                        let mut tet = vec![v(0), v(a), v(a | b), v(7)];
                        if signed_volume(&vertices, &tet) < 0.0 {
                            tet.swap(2, 3);
                        }
                        cells.push(Element {
                            kind: ElementType::Tet,
                            vertices: tet,
                            entity: 1,
                        });
                    }
                } else if use_hex {
                    cells.push(Element {
                        kind: ElementType::Hex,
                        vertices: hex,
                        entity: 1,
                    });
                } else {
                    for vertices in prisms() {
                        cells.push(Element {
                            kind: ElementType::Prism,
                            vertices,
                            entity: 1,
                        });
                    }
                }
            }
        }
    }
    LinearMesh {
        dim: 3,
        vertices,
        cells,
        ..Default::default()
    }
}

pub fn high_order(mesh: &LinearMesh, p: usize) -> HighOrderMesh {
    HighOrderMesh::from_linear(mesh, p, NodeFamily::Fekete).expect("valid test mesh")
}
