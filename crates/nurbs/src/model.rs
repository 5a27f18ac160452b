//! The geometry model: the named curves and surfaces that boundary nodes are placed on,
//! whichever input (JSON, IGES, code) described them.

use std::sync::OnceLock;

use crate::face_edges::{edges_between_faces, FaceBoundaries};
use crate::hull::SpanHulls;
use crate::inversion::{
    closest_point_on_curve, closest_point_on_curve_near, closest_point_on_surface,
    closest_point_on_surface_near, closest_point_on_surface_sampled, SurfaceSamples,
};
use crate::shapes::{AnalyticShape, ClosestPoint};
use crate::surface_groups::same_surfaces;
use crate::{NurbsCurve, NurbsSurface};

/// The carrier of a geometric entity: a curve (2D boundaries, 3D feature curves) or a surface.
#[derive(Debug, Clone, PartialEq)]
pub enum EntityGeometry {
    /// A rational B-spline curve.
    Curve(NurbsCurve),
    /// A rational B-spline surface.
    Surface(NurbsSurface),
}

/// One named curve or surface of a [`GeometryModel`].
#[derive(Debug, Clone, PartialEq)]
pub struct GeometricEntity {
    /// Name used to associate mesh physical groups with the entity (JSON `name`; for IGES
    /// the entity's label, or `"<type>#<DE>"` when it has none).
    pub name: String,
    /// Where the entity came from, for messages (e.g. `"IGES entity 128 (DE 5, line 40)"`).
    pub origin: String,
    /// The exact rational B-spline representation.
    pub geometry: EntityGeometry,
    /// The same shape in closed form, when it is one (fast, exact projection).
    pub analytic: Option<AnalyticShape>,
    /// A surface's inversion start grid, built on first use.
    pub(crate) samples: SampleCache,
    /// The boxes of the patch's knot spans, built on first use.
    pub(crate) hulls: HullCache,
}

/// The lazily built [`SurfaceSamples`] of a surface entity. It takes no part in comparisons
/// (two entities with the same shape are equal whether or not either was inverted), and a
/// grid that no longer fits the surface (its `geometry` replaced after first use) is not used.
#[derive(Debug, Clone, Default)]
pub(crate) struct SampleCache(OnceLock<SurfaceSamples>);

impl PartialEq for SampleCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// The lazily built [`SpanHulls`] of an entity (`None` inside: a weight not positive), with
/// the patch it was built for in brief ([`patch_signature`]): a cached box that no longer
/// holds the patch would wrongly prove points far from it, so one built for another patch
/// (the `geometry` replaced after first use) is not used. Takes no part in comparisons.
#[derive(Debug, Clone, Default)]
pub(crate) struct HullCache(OnceLock<(PatchSignature, Option<SpanHulls>)>);

impl PartialEq for HullCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// The control net's size, the knot vectors' ends and the first, middle and last control
/// points' bits: what a replaced patch changes, in O(1).
type PatchSignature = [u64; 16];

fn patch_signature(geometry: &EntityGeometry) -> PatchSignature {
    let (points, weights) = match geometry {
        EntityGeometry::Curve(c) => (&c.control_points, &c.weights),
        EntityGeometry::Surface(s) => (&s.control_points, &s.weights),
    };
    let (knots, other): (&[f64], &[f64]) = match geometry {
        EntityGeometry::Curve(c) => (&c.knots, &[]),
        EntityGeometry::Surface(s) => (&s.knots_u, &s.knots_v),
    };
    let mut out = [0u64; 16];
    out[0] = points.len() as u64;
    out[1] = knots.len() as u64;
    out[2] = other.len() as u64;
    let ends = |k: &[f64]| [k.first(), k.last()].map(|x| x.map_or(0, |x| x.to_bits()));
    out[3..5].copy_from_slice(&ends(knots));
    out[5..7].copy_from_slice(&ends(other));
    let n = points.len();
    for (slot, i) in [0, n / 2, n.saturating_sub(1)].into_iter().enumerate() {
        if let (Some(p), Some(w)) = (points.get(i), weights.get(i)) {
            out[7 + 3 * slot] = p[0].to_bits() ^ w.to_bits().rotate_left(17);
            out[8 + 3 * slot] = p[1].to_bits();
            out[9 + 3 * slot] = p[2].to_bits();
        }
    }
    out
}

/// A closest point on an entity: the parameter (curves use `param[0]`), the point and the
/// distance.
pub type EntityPoint = ClosestPoint<[f64; 2]>;

impl GeometricEntity {
    /// An entity without a closed form.
    pub fn new(
        name: impl Into<String>,
        origin: impl Into<String>,
        geometry: EntityGeometry,
    ) -> Self {
        Self {
            name: name.into(),
            origin: origin.into(),
            geometry,
            analytic: None,
            samples: SampleCache::default(),
            hulls: HullCache::default(),
        }
    }

    /// Whether the entity is a curve.
    pub fn is_curve(&self) -> bool {
        matches!(self.geometry, EntityGeometry::Curve(_))
    }

    /// The closest point of the entity to `x`, with its NURBS parameter. Where the entity has
    /// a closed form, the point is the closed-form one (exact) and the parameter comes from
    /// point inversion on the NURBS.
    pub fn closest_point(&self, x: [f64; 3]) -> EntityPoint {
        let inverted = self.closest_point_on_patch(x);
        match &self.analytic {
            Some(shape) => {
                let exact = shape.closest_point(x);
                ClosestPoint {
                    param: inverted.param,
                    point: exact.point,
                    distance: exact.distance,
                }
            }
            None => inverted,
        }
    }

    /// Whether every point of the entity's NURBS patch is provably farther than `r` from `x`,
    /// by the boxes of its knot spans ([`crate::hull`]) — no point inversion; `false` proves
    /// nothing (nor where a weight is not positive). A closed form reaches beyond the patch:
    /// this bounds [`Self::patch_distance`], not [`Self::distance`] of such an entity.
    pub fn patch_is_farther_than(&self, x: [f64; 3], r: f64) -> bool {
        let build = || match &self.geometry {
            EntityGeometry::Curve(c) => SpanHulls::of_curve(c),
            EntityGeometry::Surface(s) => SpanHulls::of_surface(s),
        };
        let signature = patch_signature(&self.geometry);
        let (built_for, hulls) = self.hulls.0.get_or_init(|| (signature, build()));
        if *built_for == signature {
            hulls.as_ref().is_some_and(|h| h.is_farther_than(x, r))
        } else {
            build().is_some_and(|h| h.is_farther_than(x, r))
        }
    }

    /// The distance from `x` to the entity's NURBS patch, which is bounded where its closed
    /// form is not: a CAD face's cylinder or plane is a patch around the face, its closed
    /// form the whole surface. Two faces on one infinite surface (coaxial holes, coplanar
    /// tops of stacked parts) are told apart by it.
    pub fn patch_distance(&self, x: [f64; 3]) -> f64 {
        self.closest_point_on_patch(x).distance
    }

    /// Point inversion on the NURBS alone.
    fn closest_point_on_patch(&self, x: [f64; 3]) -> EntityPoint {
        match &self.geometry {
            EntityGeometry::Curve(c) => {
                let cp = closest_point_on_curve(c, x);
                ClosestPoint {
                    param: [cp.param, 0.0],
                    point: cp.point,
                    distance: cp.distance,
                }
            }
            EntityGeometry::Surface(s) => {
                let cached = self.samples.0.get_or_init(|| SurfaceSamples::new(s));
                if cached.fits(s) {
                    closest_point_on_surface_sampled(s, cached, x)
                } else {
                    closest_point_on_surface(s, x)
                }
            }
        }
    }

    /// The point of the entity nearest `x`, without its parameter: in closed form where the
    /// entity has one (no point inversion then).
    pub fn nearest_point(&self, x: [f64; 3]) -> [f64; 3] {
        match &self.analytic {
            Some(shape) => shape.closest_point(x).point,
            None => self.closest_point(x).point,
        }
    }

    /// [`Self::nearest_point`] by a local search from the NURBS parameter `guess` (the
    /// parameter of a point found before), with the parameter found: for repeated
    /// projections of nearby points (alternating projections onto two faces), where a global
    /// inversion per step would search a grid of samples each time. Closed forms ignore
    /// `guess`.
    pub fn nearest_point_near(&self, x: [f64; 3], guess: [f64; 2]) -> ([f64; 3], [f64; 2]) {
        if let Some(shape) = &self.analytic {
            return (shape.closest_point(x).point, guess);
        }
        match &self.geometry {
            EntityGeometry::Curve(c) => {
                let cp = closest_point_on_curve_near(c, x, guess[0]);
                (cp.point, [cp.param, 0.0])
            }
            EntityGeometry::Surface(s) => {
                let cp = closest_point_on_surface_near(s, x, guess);
                (cp.point, cp.param)
            }
        }
    }

    /// The distance from `x` to the entity (closed form where available).
    pub fn distance(&self, x: [f64; 3]) -> f64 {
        match &self.analytic {
            Some(shape) => shape.closest_point(x).distance,
            None => self.closest_point(x).distance,
        }
    }

    /// The point at NURBS parameter `param` (curves use `param[0]`).
    pub fn point(&self, param: [f64; 2]) -> [f64; 3] {
        match &self.geometry {
            EntityGeometry::Curve(c) => c.point(param[0]),
            EntityGeometry::Surface(s) => s.point(param[0], param[1]),
        }
    }

    /// Diagonal of the control polygon's bounding box: the entity's size.
    pub fn size(&self) -> f64 {
        match &self.geometry {
            EntityGeometry::Curve(c) => c.size(),
            EntityGeometry::Surface(s) => s.size(),
        }
    }
}

/// A CAD edge of a 3D model: the curve the modeller gave the seam where faces meet. Faces
/// that meet tangentially (a blade's B-spline beside a linear extrusion, ~1e-5 apart over a
/// whole edge length) have no well-defined intersection to trace: their edge is this curve,
/// as Gmsh and OpenCASCADE take it.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelEdge {
    /// Where the edge came from, for messages (e.g. `"STEP #812 EDGE_CURVE (line 900)"`).
    pub origin: String,
    /// The edge's curve (a B-spline curve whole, or the piece between the edge's vertices).
    pub curve: NurbsCurve,
    /// The surface entities (indices into [`GeometryModel::entities`]) it bounds, with every
    /// entity on the same surface as one of them ([`GeometryModel::same_surface`]: the
    /// association may put a facet on any), ascending.
    pub faces: Vec<usize>,
}

/// A set of named curves and surfaces.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct GeometryModel {
    /// The entities, in input order. Their geometry is not to change once [`Self::size`]
    /// has been asked (it is kept).
    pub entities: Vec<GeometricEntity>,
    /// The CAD edges between the surface entities, where the source has its topology (STEP
    /// B-reps); empty otherwise. Not entities: no facet is associated with them.
    pub edges: Vec<ModelEdge>,
    /// The distance to which the file says its entities meet, in the model's length unit
    /// (millimetres for STEP and IGES): STEP's `UNCERTAINTY_MEASURE_WITH_UNIT` of a length,
    /// IGES's minimum user-intended resolution (Global parameter 19). Faces a modeller made
    /// separately (a fillet approximated by a B-spline beside the exact sphere it rounds)
    /// meet only to this; `None` when the source states none (exact analytic shapes).
    pub uncertainty: Option<f64>,
    /// [`Self::size`], computed on first use: the tolerances of every projection onto
    /// several entities scale with it, and computing it visits every control point (on
    /// an assembly from STEP, a quarter of the whole run was spent there).
    size: ModelSize,
    /// [`Self::same_surface`] of every entity, computed on first use.
    surfaces: SurfaceGroups,
    /// Each face's copies of its boundary curves, which [`Self::edges`] were matched from:
    /// kept so that they can be matched again to a wider uncertainty
    /// ([`Self::widen_uncertainty`]).
    edge_copies: EdgeCopies,
}

/// The model's size once computed; models are equal whatever it holds.
#[derive(Debug, Clone, Default)]
struct ModelSize(OnceLock<f64>);

impl PartialEq for ModelSize {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// The entities on one surface, once found; models are equal whatever it holds.
#[derive(Debug, Clone, Default)]
struct SurfaceGroups(OnceLock<Vec<Vec<usize>>>);

impl PartialEq for SurfaceGroups {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

/// The faces' copies of their edges; models are equal whatever it holds (the edges
/// matched from them are compared).
#[derive(Debug, Clone, Default)]
struct EdgeCopies(FaceBoundaries);

impl PartialEq for EdgeCopies {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl GeometryModel {
    /// A model of `entities` that meet to `uncertainty` (see the fields).
    pub fn new(entities: Vec<GeometricEntity>, uncertainty: Option<f64>) -> Self {
        GeometryModel {
            entities,
            edges: Vec::new(),
            uncertainty,
            size: ModelSize::default(),
            surfaces: SurfaceGroups::default(),
            edge_copies: EdgeCopies::default(),
        }
    }

    /// The CAD edges bounding every one of `faces` (entity indices, ascending).
    pub fn edges_between(&self, faces: &[usize]) -> Vec<&ModelEdge> {
        self.edges
            .iter()
            .filter(|e| faces.iter().all(|f| e.faces.binary_search(f).is_ok()))
            .collect()
    }

    /// The surface entities on the same surface as surface entity `entity`, itself included,
    /// ascending (empty for a curve or an index beyond the model): faces a modeller wrote
    /// once each with one surface — the same B-spline, or the same closed form whatever
    /// each face's patch spans. A mesh edge between facets on such faces lies on one
    /// surface, not where two meet. Found on first use; the entities' geometry is not to
    /// change after.
    pub fn same_surface(&self, entity: usize) -> &[usize] {
        self.surfaces
            .0
            .get_or_init(|| same_surfaces(&self.entities))
            .get(entity)
            .map_or(&[], Vec::as_slice)
    }

    /// How far apart two faces' copies of one edge may be and still be one edge: the
    /// file's stated uncertainty, or [`Self::round_off`] when it states less.
    pub(crate) fn edge_copy_tolerance(&self) -> f64 {
        self.uncertainty.unwrap_or(0.0).max(self.round_off())
    }

    /// Distances below which points of the model are not told apart: 1e-9 of its
    /// [`Self::size`], the round-off of evaluating and inverting its patches (a point on
    /// two coincident faces measures 0 from one and 4e-14 from the other).
    pub fn round_off(&self) -> f64 {
        1e-9 * self.size()
    }

    /// Sets the model's CAD edges from each face's copies of its boundary curves (`faces`:
    /// entity index, its curves), copies within [`Self::edge_copy_tolerance`] of each
    /// other being one edge (see [`edges_between_faces`]).
    pub(crate) fn set_edges_between_faces(&mut self, faces: FaceBoundaries) {
        let tolerance = self.edge_copy_tolerance();
        self.set_edges(edges_between_faces(&faces, tolerance));
        self.edge_copies = EdgeCopies(faces);
    }

    /// Takes the model's faces to meet to `gap` where that is more than the file states
    /// (writers often state a resolution finer than the model's real gaps between faces:
    /// OpenCASCADE's IGES writer states a fixed one), and matches the faces' copies of
    /// their edges again to it. Boundary nodes where faces meet are then held to lie
    /// within `gap` of each, instead of the file's figure. Ignored when not positive and
    /// finite.
    pub fn widen_uncertainty(&mut self, gap: f64) {
        if !(gap.is_finite() && gap > 0.0) || self.uncertainty.is_some_and(|u| u >= gap) {
            return;
        }
        self.uncertainty = Some(gap);
        if !self.edge_copies.0.is_empty() {
            let tolerance = self.edge_copy_tolerance();
            let edges = edges_between_faces(&self.edge_copies.0, tolerance);
            self.set_edges(edges);
        }
    }

    /// Sets the model's CAD edges, each widened to every face on the same surface as one it
    /// bounds ([`Self::same_surface`]: the association may put a facet on any of them).
    pub fn set_edges(&mut self, edges: Vec<ModelEdge>) {
        let widened = edges
            .into_iter()
            .map(|mut e| {
                let mut faces: Vec<usize> = e
                    .faces
                    .iter()
                    .flat_map(|&f| self.same_surface(f).iter().copied())
                    .collect();
                faces.sort_unstable();
                faces.dedup();
                e.faces = faces;
                e
            })
            .collect();
        self.edges = widened;
    }

    /// The entity called `name`, if any.
    pub fn entity(&self, name: &str) -> Option<&GeometricEntity> {
        self.entities.iter().find(|e| e.name == name)
    }

    /// Index of the entity called `name`, if any.
    pub fn index_of(&self, name: &str) -> Option<usize> {
        self.entities.iter().position(|e| e.name == name)
    }

    /// Number of curves and of surfaces.
    pub fn counts(&self) -> (usize, usize) {
        let curves = self.entities.iter().filter(|e| e.is_curve()).count();
        (curves, self.entities.len() - curves)
    }

    /// Model size: the largest entity size (for relative tolerances).
    pub fn size(&self) -> f64 {
        *self
            .size
            .0
            .get_or_init(|| self.entities.iter().map(|e| e.size()).fold(0.0, f64::max))
    }
}

#[cfg(test)]
#[path = "tests/model.rs"]
mod tests;
