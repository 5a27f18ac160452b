//! What assembly needs of one reference element beyond the shared
//! [`hocurve_nodes::ReferenceElement`] (whose tabulated quadrature it holds): vertex shape
//! functions at the nodes and the reference stiffness matrices of simplices.

use std::collections::{BTreeMap, HashMap};
use std::sync::{Arc, Mutex, OnceLock};

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use hocurve_mesh::HighOrderMesh;

use hocurve_nodes::{NodeFamily, ReferenceElement, Shape, TabulatedBasis};

use crate::ElasticError;

/// The stiffness data of one shape at the mesh's order and node family.
#[derive(Debug, Clone)]
pub(crate) struct ReferenceStiffness {
    pub shape: Shape,
    /// Topological dimension (= mesh dimension).
    pub dim: usize,
    /// Number of nodes n.
    pub len: usize,
    /// Order and node family of the element.
    pub order: usize,
    pub family: NodeFamily,
    /// Vertex shape functions Nᵥ(ξⱼ) at each node ξⱼ (`[j][v]`): the straight-sided map and
    /// the p = 1 → p prolongation.
    pub vertex_weights: Vec<[f64; 8]>,
    /// Simplices only: the reference matrices S_αβ[i][j] = ∫ ∂Φᵢ/∂ξ_α ∂Φⱼ/∂ξ_β dξ, at index
    /// `α * dim + β`, each n × n row-major.
    pub simplex_stiffness: Option<Vec<Vec<f64>>>,
    /// Prisms only: the same matrices, which give the stiffness of prisms whose map is
    /// affine (the top triangle a translate of the bottom one: extruded meshes).
    pub prism_stiffness: Option<Vec<Vec<f64>>>,
    /// Degree-2p rule for the stiffness of non-affine cells.
    pub stiffness_rule: Arc<TabulatedBasis>,
    /// Degree-(2p + 2) rule for loads and error norms.
    pub load_rule: Arc<TabulatedBasis>,
    /// The rank factors of the reference matrices, built once on first use
    /// ([`crate::matrix_free`]).
    pub(crate) gradient_factors: OnceLock<Arc<crate::matrix_free::ReferenceGradients>>,
}

/// (shape, order, node family).
type Key = (Shape, usize, NodeFamily);

impl ReferenceStiffness {
    pub fn new(shape: Shape, order: usize, family: NodeFamily) -> Result<Self, ElasticError> {
        let element = ReferenceElement::shared(shape, order, family)?;
        let nodes = element.nodes();
        let dim = shape.dim();
        let len = nodes.len();
        let vertex_weights = nodes
            .points()
            .iter()
            .map(|&xi| shape.vertex_shape_functions(xi).0)
            .collect();
        // The symmetric rule: on prisms 48 points instead of 64 at p = 3 (the matrix-free
        // action of a curved-layer prism costs in proportion, see crate::matrix_free).
        let stiffness_rule = element.symmetric_quadrature(2 * order);
        let load_rule = element.quadrature(2 * order + 2);
        // ∂Φᵢ/∂ξ_α is of degree p − 1 on simplices (and on the prism of degree 2p − 2 in the
        // triangle's and 2p in ζ after multiplication), so the degree-2p rule is exact.
        let simplex_stiffness = matches!(shape, Shape::Tri | Shape::Tet)
            .then(|| reference_matrices(&stiffness_rule, dim, len));
        let prism_stiffness =
            (shape == Shape::Prism).then(|| reference_matrices(&stiffness_rule, dim, len));
        Ok(ReferenceStiffness {
            shape,
            dim,
            len,
            order,
            family,
            vertex_weights,
            simplex_stiffness,
            prism_stiffness,
            stiffness_rule,
            load_rule,
            gradient_factors: OnceLock::new(),
        })
    }

    /// The reference data of `shape` at `order` and `family`, built once per process (the
    /// p-multigrid asks for every order below the mesh's at every solve, and at p = 10 the
    /// tetrahedron's matrices alone take a quarter of a second).
    pub fn shared(
        shape: Shape,
        order: usize,
        family: NodeFamily,
    ) -> Result<Arc<Self>, ElasticError> {
        static CACHE: OnceLock<Mutex<HashMap<Key, Arc<ReferenceStiffness>>>> = OnceLock::new();
        let cache = CACHE.get_or_init(|| Mutex::new(HashMap::new()));
        let lock = || {
            cache
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner())
        };
        let key = (shape, order, family);
        if let Some(hit) = lock().get(&key) {
            return Ok(Arc::clone(hit));
        }
        // Built outside the lock; two threads building the same data get identical results.
        let built = Arc::new(ReferenceStiffness::new(shape, order, family)?);
        Ok(Arc::clone(lock().entry(key).or_insert(built)))
    }

    /// The reference elements of every shape present in `mesh`, after checking that each cell
    /// has the mesh's dimension and the right number of nodes.
    pub fn for_mesh(mesh: &HighOrderMesh) -> Result<BTreeMap<Shape, Arc<Self>>, ElasticError> {
        let mut out = BTreeMap::new();
        for (c, cell) in mesh.cells.iter().enumerate() {
            let shape = cell.kind;
            if shape.dim() != mesh.dim {
                return Err(ElasticError::WrongCellDimension {
                    cell: c,
                    kind: shape.name(),
                    dim: mesh.dim,
                });
            }
            if let std::collections::btree_map::Entry::Vacant(slot) = out.entry(shape) {
                slot.insert(ReferenceStiffness::shared(shape, mesh.order, mesh.family)?);
            }
            let expected = shape.num_nodes(mesh.order);
            if cell.nodes.len() != expected {
                return Err(ElasticError::WrongNodeCount {
                    cell: c,
                    found: cell.nodes.len(),
                    expected,
                });
            }
            if let Some(&bad) = cell.nodes.iter().find(|&&n| n as usize >= mesh.nodes.len()) {
                return Err(ElasticError::NodeOutOfRange {
                    node: bad,
                    count: mesh.nodes.len(),
                });
            }
        }
        Ok(out)
    }

    /// Whether a prism with node coordinates `coords` has an affine map: its top triangle the
    /// bottom one translated (vertex v + 3 = vertex v + the same vector) and every node at its
    /// straight-sided position. Its Jacobian is then constant, with columns x₁ − x₀, x₂ − x₀,
    /// x₃ − x₀.
    pub fn is_affine_prism(&self, coords: &[[f64; 3]]) -> bool {
        if self.prism_stiffness.is_none() || coords.len() != self.len {
            return false;
        }
        let mut size = 0.0f64;
        for v in 1..6 {
            for d in 0..3 {
                size = size.max((coords[v][d] - coords[0][d]).abs());
            }
        }
        let tolerance = 1e-10 * size;
        let height = |v: usize| [0, 1, 2].map(|d| coords[v + 3][d] - coords[v][d]);
        let (h0, h1, h2) = (height(0), height(1), height(2));
        let translated = (0..3)
            .all(|d| (h1[d] - h0[d]).abs() <= tolerance && (h2[d] - h0[d]).abs() <= tolerance);
        translated
            && coords.iter().zip(&self.vertex_weights).all(|(x, w)| {
                (0..3).all(|d| {
                    let straight: f64 = (0..6).map(|v| w[v] * coords[v][d]).sum();
                    (x[d] - straight).abs() <= tolerance
                })
            })
    }

    /// Whether a simplex with node coordinates `coords` is straight-sided, i.e. every node
    /// sits where the affine map of the vertices puts it (so its Jacobian is constant).
    pub fn is_affine_simplex(&self, coords: &[[f64; 3]]) -> bool {
        if self.simplex_stiffness.is_none() {
            return false;
        }
        let nv = self.shape.num_vertices();
        let mut size = 0.0f64;
        for v in 1..nv {
            for d in 0..3 {
                size = size.max((coords[v][d] - coords[0][d]).abs());
            }
        }
        let tolerance = 1e-10 * size;
        coords.iter().zip(&self.vertex_weights).all(|(x, w)| {
            (0..3).all(|d| {
                let straight: f64 = (0..nv).map(|v| w[v] * coords[v][d]).sum();
                (x[d] - straight).abs() <= tolerance
            })
        })
    }
}

/// S_αβ[i][j] = ∫ ∂Φᵢ/∂ξ_α ∂Φⱼ/∂ξ_β dξ by `rule`, at index `α dim + β`, each n × n
/// row-major: S_αβ = G_αᵀ W G_β with G_α[q][i] = ∂Φᵢ/∂ξ_α(ξ_q), W the weights, by faer's
/// matrix product (sequential: the same bits for any thread count), and S_βα = S_αβᵀ.
fn reference_matrices(rule: &TabulatedBasis, dim: usize, len: usize) -> Vec<Vec<f64>> {
    let points = rule.len();
    let gradients: Vec<Mat<f64>> = (0..dim)
        .map(|alpha| Mat::from_fn(points, len, |q, i| rule.gradients(q)[i][alpha]))
        .collect();
    let weighted: Vec<Mat<f64>> = gradients
        .iter()
        .map(|g| Mat::from_fn(points, len, |q, i| rule.weights()[q] * g[(q, i)]))
        .collect();
    let mut s = vec![Vec::new(); dim * dim];
    for alpha in 0..dim {
        for beta in alpha..dim {
            let mut product = Mat::<f64>::zeros(len, len);
            matmul(
                product.as_mut(),
                Accum::Replace,
                gradients[alpha].transpose(),
                weighted[beta].as_ref(),
                1.0,
                Par::Seq,
            );
            s[alpha * dim + beta] = (0..len * len)
                .map(|k| product[(k / len, k % len)])
                .collect();
            if beta != alpha {
                s[beta * dim + alpha] = (0..len * len)
                    .map(|k| product[(k % len, k / len)])
                    .collect();
            }
        }
    }
    s
}

#[cfg(test)]
#[path = "tests/reference_element.rs"]
mod tests;
