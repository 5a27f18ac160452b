//! Repair of the elements the certification did not find valid (beyond the paper, whose
//! elastic analogy does not guarantee det J > 0): the nodes around them that lie on no
//! boundary are untangled by a Jacobian-barrier optimisation ([`hocurve_untangle`]), the
//! boundary nodes staying on the geometry, in patches that widen by one ring of cells per
//! round (at most [`MAX_UNTANGLE_RINGS`]) until every element is certified.

use std::collections::BTreeSet;

use hocurve_mesh::HighOrderMesh;
use hocurve_quality::{MeshQuality, Validity};
use hocurve_untangle::{untangle, UntangleOptions};

use crate::pipeline::{invalid_cells, CurveError};

/// Rings of neighbouring cells the widest untangling patch reaches.
pub const MAX_UNTANGLE_RINGS: usize = 3;

/// What the untangling did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Untangling {
    /// Elements not certified valid when the untangling started.
    pub elements: usize,
    /// Rounds run (patch rings 1, 2, ...).
    pub rounds: usize,
}

/// The elements with det J ≤ 0 found, or that the Bézier check left undecided.
pub fn not_certified(quality: &MeshQuality) -> Vec<usize> {
    let mut cells: BTreeSet<usize> = invalid_cells(quality).into_iter().collect();
    if let Some(checks) = &quality.validity {
        cells.extend(
            checks
                .iter()
                .enumerate()
                .filter(|(_, c)| c.validity == Validity::Undecided)
                .map(|(e, _)| e),
        );
    }
    cells.into_iter().collect()
}

/// Untangles the patches around the elements of `mesh` that `quality` does not certify,
/// widening them round by round, and returns the quality of the repaired mesh (measured by
/// `assess`, which must certify). `straight` holds the straight-sided node positions (the
/// shapes aimed at); `on_geometry` the nodes placed on the geometry, which stay where they
/// are, like every other node on the boundary; `hopeless` the cells no node move can make
/// valid (two faces on one curved entity meeting along an edge), which are not tried.
pub(crate) fn untangle_not_certified(
    mesh: &mut HighOrderMesh,
    straight: &[[f64; 3]],
    on_geometry: impl IntoIterator<Item = u32>,
    hopeless: &[usize],
    mut quality: MeshQuality,
    assess: &dyn Fn(&HighOrderMesh) -> Result<MeshQuality, CurveError>,
) -> Result<(MeshQuality, Untangling), CurveError> {
    let mut done = Untangling::default();
    // Cells whose det J vanishes on a boundary edge whatever the free nodes do are left out.
    let repairable = |quality: &MeshQuality| -> Vec<usize> {
        not_certified(quality)
            .into_iter()
            .filter(|c| !hopeless.contains(c))
            .collect()
    };
    let mut bad = repairable(&quality);
    if bad.is_empty() || quality.validity.is_none() {
        return Ok((quality, done));
    }
    done.elements = bad.len();
    let mut fixed: BTreeSet<u32> = on_geometry.into_iter().collect();
    fixed.extend(
        mesh.boundary_facet_nodes()?
            .into_iter()
            .flat_map(|(_, nodes)| nodes),
    );
    let fixed: Vec<u32> = fixed.into_iter().collect();
    for rings in 1..=MAX_UNTANGLE_RINGS {
        let options = UntangleOptions {
            rings,
            ..UntangleOptions::default()
        };
        untangle(mesh, straight, &bad, &fixed, &options)?;
        done.rounds = rings;
        quality = assess(mesh)?;
        bad = repairable(&quality);
        if bad.is_empty() {
            break;
        }
    }
    Ok((quality, done))
}
