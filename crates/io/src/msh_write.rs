//! Gmsh MSH writer for high-order meshes: MSH 4.1 (Gmsh's default) or 2.2 (what MFEM,
//! NekMesh and older tools ask for), ASCII or binary ([`MshFormat`]).
//!
//! Elements are Gmsh's complete order-p elements (`MSH_TRI_10`, `MSH_TET_35`,
//! `MSH_HEX_125`, …), their nodes in Gmsh's order (see [`crate::ordering`]); the declared
//! facets are written too, at the same order, on their own entities. What is written:
//! - `$PhysicalNames`: the physical groups that have a name (unnamed groups live on in the
//!   entities' physical tags);
//! - `$Entities`: one curve/surface/volume per distinct (dimension, entity tag) of the cells
//!   and facets, with its physical tags and the bounding box of its elements' nodes, no
//!   bounding entities;
//! - `$Nodes` (4.1): node tags 1..N in the mesh's node order, in that order in the file; each node
//!   is classified on the lowest-dimensional entity (then smallest tag) among those whose
//!   elements use it, as Gmsh itself classifies boundary nodes on the boundary surface; a
//!   block per run of consecutive nodes on the same entity (an entity may have several);
//! - `$Elements` (4.1): facets then cells, in their order in the mesh, one block per run of
//!   consecutive elements with the same entity and type; element tags 1, 2, ….
//! - MSH 2.2 has no `$Entities`: nodes are listed with their tags 1..N, elements as `tag
//!   type 2 physical entity nodes…`, one copy of an element per physical group of its
//!   entity (as Gmsh writes 2.2), physical tag 0 when it has none.
//! - Binary files hold the same records as little-endian bytes, laid out as Gmsh writes
//!   them (`-bin`): 4.1 with 8-byte `size_t` counts and tags, 2.2 with 4-byte `int`s; the
//!   section keywords, physical names and data headers stay text.
//!
//! - `$NodeData` / `$ElementData` ([`write_msh_with`]): one view per data array (scalar or
//!   3-vector; string tag its name, real tag time 0, integer tags time step 0, the number
//!   of components and of values), values per node tag and per cell's element tag.
//!
//! Coordinates and data are written in Rust's shortest round-trip form (`{:?}`), so reading
//! the file back gives bitwise the same values. Same input, same bytes.

use std::collections::BTreeMap;
use std::io::Write;
use std::ops::Range;
use std::path::Path;

use rayon::prelude::*;

use hocurve_mesh::{HighOrderElement, HighOrderMesh};
use hocurve_nodes::Shape;

use crate::atomic::write_atomically;
use crate::ordering::{gmsh_element_type, gmsh_max_order, gmsh_permutation};
use crate::vtu_write::check_arrays;
use crate::{DataArray, IoError};

/// The MSH version to write.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum MshVersion {
    /// MSH 2.2: no entities section; elements carry (physical, entity) tags.
    V2_2,
    /// MSH 4.1, Gmsh's current format.
    #[default]
    V4_1,
}

impl MshVersion {
    /// The version as the `$MeshFormat` header spells it.
    pub fn number(self) -> &'static str {
        match self {
            MshVersion::V2_2 => "2.2",
            MshVersion::V4_1 => "4.1",
        }
    }
}

/// How a `.msh` file is written: version and encoding (default: 4.1 ASCII).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct MshFormat {
    /// MSH 2.2 or 4.1.
    pub version: MshVersion,
    /// Binary (little-endian, Gmsh's `-bin`) instead of ASCII.
    pub binary: bool,
}

/// Writes `mesh` to `path` as a Gmsh MSH 4.1 ASCII file with complete order-p elements.
///
/// Fails before touching the file when an element has no Gmsh type at the mesh's order
/// (Gmsh's complete elements stop at order 10 for lines, triangles, quadrilaterals and
/// tetrahedra, 9 for hexahedra and prisms), when an element's node count or node ids are
/// inconsistent, when a coordinate is not finite or a physical name cannot be quoted.
pub fn write_msh(path: &Path, mesh: &HighOrderMesh) -> Result<(), IoError> {
    write_msh_with(path, mesh, &[], &[])
}

/// [`write_msh`] with nodal and cell data: each point-data array (`components` ∈ {1, 3}
/// values per node of `mesh`) becomes a `$NodeData` view, each cell-data array (per cell)
/// an `$ElementData` view over the cells' element tags (facets get none). Arrays are
/// checked like [`crate::write_vtu_with`]'s (length, distinct non-empty names, finite
/// values) before the file is touched; names must not hold a quote or a line break.
pub fn write_msh_with(
    path: &Path,
    mesh: &HighOrderMesh,
    point_data: &[DataArray],
    cell_data: &[DataArray],
) -> Result<(), IoError> {
    write_msh_as(path, mesh, point_data, cell_data, MshFormat::default())
}

/// [`write_msh_with`] in the given version and encoding. MSH 2.2 stores tags as 4-byte
/// integers: a mesh with more nodes or elements than that holds is refused.
pub fn write_msh_as(
    path: &Path,
    mesh: &HighOrderMesh,
    point_data: &[DataArray],
    cell_data: &[DataArray],
    format: MshFormat,
) -> Result<(), IoError> {
    let bad = |message: String| IoError::Unsupported {
        path: path.to_path_buf(),
        message,
    };
    if mesh.family != hocurve_nodes::NodeFamily::Equispaced && mesh.order > 2 {
        // Gmsh places high-order nodes equispaced; other positions would change the geometry.
        return Err(bad(format!(
            "the mesh has {} nodes; Gmsh high-order elements need equispaced nodes: resample it with HighOrderMesh::resampled (write_mesh does)",
            mesh.family
        )));
    }
    let plan = Plan::new(mesh).map_err(bad)?;
    check_arrays("point", point_data, mesh.nodes.len()).map_err(bad)?;
    check_arrays("cell", cell_data, mesh.cells.len()).map_err(bad)?;
    for a in point_data.iter().chain(cell_data) {
        if a.components != 1 && a.components != 3 {
            return Err(bad(format!(
                "data '{}' has {} components; Gmsh views hold scalars (1) or vectors (3)",
                a.name, a.components
            )));
        }
        if a.name.contains('"') || a.name.contains('\n') || a.name.contains('\r') {
            return Err(bad(format!(
                "data name {:?} has a quote or line break, which MSH cannot store",
                a.name
            )));
        }
    }
    if format.version == MshVersion::V2_2 {
        let (_, elements) = plan.tags_2(mesh);
        if mesh.nodes.len().max(elements) > i32::MAX as usize {
            return Err(bad(format!(
                "{} nodes and {elements} elements: MSH 2.2 numbers them with 4-byte integers; write MSH 4.1",
                mesh.nodes.len()
            )));
        }
    }
    write_atomically(path, |w| {
        plan.write(w, mesh, format)
            .and_then(|()| plan.write_data(w, mesh, point_data, cell_data, format))
            .map_err(|source| IoError::Os {
                path: path.to_path_buf(),
                source,
            })
    })
}

/// An element list (facets or cells) with its dimension.
struct Group<'a> {
    dim: usize,
    elements: &'a [HighOrderElement],
    shapes: Vec<Shape>,
}

/// Everything decided before writing.
struct Plan<'a> {
    groups: Vec<Group<'a>>,
    /// Entities sorted by (dim, tag), with their bounding boxes.
    entities: Vec<((usize, i32), [f64; 6])>,
    /// Entity index (into `entities`) each node is classified on.
    node_entity: Vec<usize>,
    /// Gmsh type and permutation (Gmsh order → canonical) per shape.
    types: BTreeMap<Shape, (i32, Vec<usize>)>,
}

impl<'a> Plan<'a> {
    fn new(mesh: &'a HighOrderMesh) -> Result<Self, String> {
        let p = mesh.order;
        if mesh.dim != 2 && mesh.dim != 3 {
            return Err(format!("mesh dimension {} (expected 2 or 3)", mesh.dim));
        }
        if mesh.cells.is_empty() {
            return Err("the mesh has no cells".into());
        }
        if let Some(i) = mesh
            .nodes
            .iter()
            .position(|x| x.iter().any(|c| !c.is_finite()))
        {
            return Err(format!(
                "node {i} has a non-finite coordinate {:?}",
                mesh.nodes[i]
            ));
        }
        for g in &mesh.physical_groups {
            if g.name.contains('"') || g.name.contains('\n') || g.name.contains('\r') {
                return Err(format!(
                    "physical group {} ({}D) has a name with a quote or line break, which MSH cannot store: {:?}",
                    g.tag, g.dim, g.name
                ));
            }
        }
        let mut groups = Vec::new();
        let mut types = BTreeMap::new();
        for (what, dim, elements) in [
            ("facet", mesh.dim - 1, &mesh.facets),
            ("cell", mesh.dim, &mesh.cells),
        ] {
            let mut shapes = Vec::with_capacity(elements.len());
            for (i, e) in elements.iter().enumerate() {
                let shape = e.kind;
                if shape.dim() != dim {
                    return Err(format!(
                        "{what} {i} is a {}, expected dimension {dim}",
                        shape.name()
                    ));
                }
                if e.nodes.len() != shape.num_nodes(p) {
                    return Err(format!(
                        "{what} {i} ({}) has {} nodes, expected {} at order {p}",
                        shape.name(),
                        e.nodes.len(),
                        shape.num_nodes(p)
                    ));
                }
                if let Some(&n) = e.nodes.iter().find(|&&n| n as usize >= mesh.nodes.len()) {
                    return Err(format!(
                        "{what} {i} references node {n}, but the mesh has {} nodes",
                        mesh.nodes.len()
                    ));
                }
                if let std::collections::btree_map::Entry::Vacant(slot) = types.entry(shape) {
                    let t = gmsh_element_type(shape, p).ok_or_else(|| {
                        format!(
                            "Gmsh has no order-{p} {} element (its complete {} elements go up to order {})",
                            shape.name(),
                            shape.name(),
                            gmsh_max_order(shape)
                        )
                    })?;
                    slot.insert((t, gmsh_permutation(shape, p)));
                }
                shapes.push(shape);
            }
            groups.push(Group {
                dim,
                elements,
                shapes,
            });
        }

        // Entities and their bounding boxes.
        let empty = [
            f64::INFINITY,
            f64::INFINITY,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
            f64::NEG_INFINITY,
        ];
        // Elements come in runs of one entity: one map lookup per run.
        let mut boxes: BTreeMap<(usize, i32), [f64; 6]> = BTreeMap::new();
        for g in &groups {
            for run in g.elements.chunk_by(|a, b| a.entity == b.entity) {
                // Min and max in any order: the same box for any thread count.
                let widen = |mut b: [f64; 6], x: [f64; 3]| {
                    for d in 0..3 {
                        b[d] = b[d].min(x[d]);
                        b[d + 3] = b[d + 3].max(x[d]);
                    }
                    b
                };
                let run_box = run
                    .par_iter()
                    .with_min_len(1024)
                    .fold(
                        || empty,
                        |b, e| {
                            e.nodes
                                .iter()
                                .fold(b, |b, &n| widen(b, mesh.nodes[n as usize]))
                        },
                    )
                    .reduce(
                        || empty,
                        |a, c| widen(widen(a, [c[0], c[1], c[2]]), [c[3], c[4], c[5]]),
                    );
                let b = boxes.entry((g.dim, run[0].entity)).or_insert(empty);
                *b = widen(
                    widen(*b, [run_box[0], run_box[1], run_box[2]]),
                    [run_box[3], run_box[4], run_box[5]],
                );
            }
        }
        let entities: Vec<((usize, i32), [f64; 6])> = boxes.into_iter().collect();
        let index: BTreeMap<(usize, i32), usize> = entities
            .iter()
            .enumerate()
            .map(|(i, (k, _))| (*k, i))
            .collect();

        // Classification: the smallest entity index (lowest dimension, then tag) using it.
        let mut node_entity = vec![usize::MAX; mesh.nodes.len()];
        for g in &groups {
            for run in g.elements.chunk_by(|a, b| a.entity == b.entity) {
                let k = index[&(g.dim, run[0].entity)];
                for e in run {
                    for &n in &e.nodes {
                        let slot = &mut node_entity[n as usize];
                        *slot = (*slot).min(k);
                    }
                }
            }
        }
        // Nodes no element uses (none in a mesh built by hocurve) go to the first cell entity.
        let fallback = entities
            .iter()
            .position(|((d, _), _)| *d == mesh.dim)
            .unwrap_or(0);
        for slot in &mut node_entity {
            if *slot == usize::MAX {
                *slot = fallback;
            }
        }
        Ok(Plan {
            groups,
            entities,
            node_entity,
            types,
        })
    }

    fn write<W: Write + Send>(
        &self,
        w: &mut W,
        mesh: &HighOrderMesh,
        format: MshFormat,
    ) -> std::io::Result<()> {
        let binary = format.binary;
        writeln!(
            w,
            "$MeshFormat\n{} {} 8",
            format.version.number(),
            u8::from(binary)
        )?;
        if binary {
            // The integer 1 in the writer's byte order, for the reader to check it.
            w.write_all(&1i32.to_le_bytes())?;
            writeln!(w)?;
        }
        writeln!(w, "$EndMeshFormat")?;

        let named: Vec<_> = mesh
            .physical_groups
            .iter()
            .filter(|g| !g.name.is_empty())
            .collect();
        if !named.is_empty() {
            writeln!(w, "$PhysicalNames\n{}", named.len())?;
            for g in named {
                writeln!(w, "{} {} \"{}\"", g.dim, g.tag, g.name)?;
            }
            writeln!(w, "$EndPhysicalNames")?;
        }
        match format.version {
            MshVersion::V4_1 => {
                self.write_entities(w, mesh, binary)?;
                self.write_nodes_4(w, mesh, binary)?;
                self.write_elements_4(w, binary)
            }
            MshVersion::V2_2 => {
                self.write_nodes_2(w, mesh, binary)?;
                self.write_elements_2(w, mesh, binary)
            }
        }
    }

    /// `$Entities` (MSH 4.1): bounding boxes and physical tags, no bounding entities.
    fn write_entities<W: Write>(
        &self,
        w: &mut W,
        mesh: &HighOrderMesh,
        binary: bool,
    ) -> std::io::Result<()> {
        writeln!(w, "$Entities")?;
        let count = |d: usize| self.entities.iter().filter(|((e, _), _)| *e == d).count();
        let mut out = Vec::new();
        if binary {
            for c in [0, count(1), count(2), count(3)] {
                push_size(&mut out, c);
            }
        } else {
            writeln!(out, "0 {} {} {}", count(1), count(2), count(3))?;
        }
        for ((dim, tag), b) in &self.entities {
            let physicals = mesh.physical_tags(*dim, *tag);
            if binary {
                out.extend_from_slice(&tag.to_le_bytes());
                b.iter()
                    .for_each(|v| out.extend_from_slice(&v.to_le_bytes()));
                push_size(&mut out, physicals.len());
                physicals
                    .iter()
                    .for_each(|t| out.extend_from_slice(&t.to_le_bytes()));
                push_size(&mut out, 0);
            } else {
                push_integer(&mut out, *tag as i64);
                for &v in b {
                    out.push(b' ');
                    push_float(&mut out, v);
                }
                write!(out, " {}", physicals.len())?;
                for t in physicals {
                    write!(out, " {t}")?;
                }
                writeln!(out, " 0")?;
            }
        }
        w.write_all(&out)?;
        end_section(w, "Entities", binary)
    }

    /// Runs of consecutive nodes classified on the same entity: `$Nodes` blocks (MSH 4.1),
    /// so that node tags 1..N appear in increasing order (readers that number nodes by
    /// appearance get the mesh's own numbering back); an entity may own several blocks.
    fn node_runs(&self) -> Vec<Range<usize>> {
        let mut runs = Vec::new();
        let mut start = 0;
        for i in 1..=self.node_entity.len() {
            if i == self.node_entity.len() || self.node_entity[i] != self.node_entity[start] {
                runs.push(start..i);
                start = i;
            }
        }
        runs
    }

    fn write_nodes_4<W: Write + Send>(
        &self,
        w: &mut W,
        mesh: &HighOrderMesh,
        binary: bool,
    ) -> std::io::Result<()> {
        writeln!(w, "$Nodes")?;
        let runs = self.node_runs();
        let n = mesh.nodes.len();
        let header = [runs.len(), n, n.min(1), n];
        write_sizes(w, &header, binary)?;
        for run in runs {
            let ((dim, tag), _) = self.entities[self.node_entity[run.start]];
            if binary {
                let mut h = Vec::with_capacity(20);
                for v in [dim as i32, tag, 0] {
                    h.extend_from_slice(&v.to_le_bytes());
                }
                push_size(&mut h, run.len());
                w.write_all(&h)?;
                write_records(w, run.clone(), |i, t| {
                    push_size(t, i + 1);
                    Ok(())
                })?;
                write_records(w, run, |i, t| {
                    mesh.nodes[i]
                        .iter()
                        .for_each(|x| t.extend_from_slice(&x.to_le_bytes()));
                    Ok(())
                })?;
            } else {
                writeln!(w, "{dim} {tag} 0 {}", run.len())?;
                write_records(w, run.clone(), |i, t| {
                    push_integer(t, i as i64 + 1);
                    t.push(b'\n');
                    Ok(())
                })?;
                write_records(w, run, |i, t| {
                    push_coordinates(t, mesh.nodes[i]);
                    Ok(())
                })?;
            }
        }
        end_section(w, "Nodes", binary)
    }

    /// Runs of consecutive elements with the same (entity, shape): (group, range).
    fn element_runs(&self) -> Vec<(usize, Range<usize>)> {
        let mut runs = Vec::new();
        for (g, group) in self.groups.iter().enumerate() {
            let mut start = 0;
            for i in 1..=group.elements.len() {
                let split = i == group.elements.len()
                    || group.elements[i].entity != group.elements[start].entity
                    || group.shapes[i] != group.shapes[start];
                if split {
                    runs.push((g, start..i));
                    start = i;
                }
            }
        }
        runs
    }

    fn write_elements_4<W: Write + Send>(&self, w: &mut W, binary: bool) -> std::io::Result<()> {
        writeln!(w, "$Elements")?;
        let runs = self.element_runs();
        let total: usize = self.groups.iter().map(|g| g.elements.len()).sum();
        write_sizes(w, &[runs.len(), total, total.min(1), total], binary)?;
        let mut tag = 0usize;
        for (g, run) in runs {
            let group = &self.groups[g];
            let shape = group.shapes[run.start];
            let (gmsh_type, perm) = &self.types[&shape];
            let entity = group.elements[run.start].entity;
            let first_tag = tag + 1 - run.start;
            tag += run.len();
            if binary {
                let mut h = Vec::with_capacity(20);
                for v in [group.dim as i32, entity, *gmsh_type] {
                    h.extend_from_slice(&v.to_le_bytes());
                }
                push_size(&mut h, run.len());
                w.write_all(&h)?;
                write_records(w, run, |i, t| {
                    push_size(t, first_tag + i);
                    for &k in perm {
                        push_size(t, group.elements[i].nodes[k] as usize + 1);
                    }
                    Ok(())
                })?;
            } else {
                writeln!(w, "{} {entity} {gmsh_type} {}", group.dim, run.len())?;
                write_records(w, run, |i, t| {
                    push_integer(t, (first_tag + i) as i64);
                    for &k in perm {
                        t.push(b' ');
                        push_integer(t, group.elements[i].nodes[k] as i64 + 1);
                    }
                    t.push(b'\n');
                    Ok(())
                })?;
            }
        }
        end_section(w, "Elements", binary)
    }

    /// `$Nodes` in MSH 2.2: the count, then tag and coordinates per node.
    fn write_nodes_2<W: Write + Send>(
        &self,
        w: &mut W,
        mesh: &HighOrderMesh,
        binary: bool,
    ) -> std::io::Result<()> {
        writeln!(w, "$Nodes\n{}", mesh.nodes.len())?;
        write_records(w, 0..mesh.nodes.len(), |i, t| {
            if binary {
                t.extend_from_slice(&(i as i32 + 1).to_le_bytes());
                mesh.nodes[i]
                    .iter()
                    .for_each(|x| t.extend_from_slice(&x.to_le_bytes()));
            } else {
                push_integer(t, i as i64 + 1);
                t.push(b' ');
                push_coordinates(t, mesh.nodes[i]);
            }
            Ok(())
        })?;
        end_section(w, "Nodes", binary)
    }

    /// The physical tags an element of entity (`dim`, `entity`) is written with in MSH 2.2:
    /// one copy of the element per physical group of its entity, as Gmsh writes it, or one
    /// with physical tag 0 when the entity is in none.
    fn copies_2(mesh: &HighOrderMesh, dim: usize, entity: i32) -> &[i32] {
        match mesh.physical_tags(dim, entity) {
            [] => &[0],
            tags => tags,
        }
    }

    /// The element tag of each element's first copy in MSH 2.2, per group, and the total
    /// number of elements written.
    fn tags_2(&self, mesh: &HighOrderMesh) -> (Vec<Vec<usize>>, usize) {
        let mut next = 1;
        let tags = self
            .groups
            .iter()
            .map(|g| {
                let mut tags = Vec::with_capacity(g.elements.len());
                for run in g.elements.chunk_by(|a, b| a.entity == b.entity) {
                    let copies = Self::copies_2(mesh, g.dim, run[0].entity).len();
                    for _ in run {
                        tags.push(next);
                        next += copies;
                    }
                }
                tags
            })
            .collect();
        (tags, next - 1)
    }

    /// `$Elements` in MSH 2.2: `tag type 2 physical entity nodes…` per element (binary:
    /// a header `type count 2` per run of one type).
    fn write_elements_2<W: Write + Send>(
        &self,
        w: &mut W,
        mesh: &HighOrderMesh,
        binary: bool,
    ) -> std::io::Result<()> {
        let (tags, total) = self.tags_2(mesh);
        writeln!(w, "$Elements\n{total}")?;
        for (g, run) in self.element_runs() {
            let group = &self.groups[g];
            let (gmsh_type, perm) = &self.types[&group.shapes[run.start]];
            let entity = group.elements[run.start].entity;
            let physicals = Self::copies_2(mesh, group.dim, entity);
            if binary {
                let mut h = Vec::with_capacity(12);
                for v in [*gmsh_type, (run.len() * physicals.len()) as i32, 2] {
                    h.extend_from_slice(&v.to_le_bytes());
                }
                w.write_all(&h)?;
            }
            write_records(w, run, |i, t| {
                let e = &group.elements[i];
                for (copy, &physical) in physicals.iter().enumerate() {
                    let tag = tags[g][i] + copy;
                    if binary {
                        for v in [tag as i32, physical, entity] {
                            t.extend_from_slice(&v.to_le_bytes());
                        }
                        for &k in perm {
                            t.extend_from_slice(&(e.nodes[k] as i32 + 1).to_le_bytes());
                        }
                    } else {
                        write!(t, "{tag} {gmsh_type} 2 {physical} {entity}")?;
                        for &k in perm {
                            t.push(b' ');
                            push_integer(t, e.nodes[k] as i64 + 1);
                        }
                        t.push(b'\n');
                    }
                }
                Ok(())
            })?;
        }
        end_section(w, "Elements", binary)
    }

    /// The `$NodeData` and `$ElementData` views (arrays already checked): values per node
    /// tag, and per element tag of the cells (every copy of a cell in MSH 2.2).
    fn write_data<W: Write + Send>(
        &self,
        w: &mut W,
        mesh: &HighOrderMesh,
        point_data: &[DataArray],
        cell_data: &[DataArray],
        format: MshFormat,
    ) -> std::io::Result<()> {
        let binary = format.binary;
        // Element tags of the cells' copies: MSH 4.1 numbers facets 1..=F then cells.
        let cell_copies: Vec<(usize, usize)> = match format.version {
            MshVersion::V4_1 => (0..mesh.cells.len())
                .map(|i| (mesh.facets.len() + 1 + i, 1))
                .collect(),
            MshVersion::V2_2 => {
                let (tags, _) = self.tags_2(mesh);
                let cells = &self.groups[1];
                (0..mesh.cells.len())
                    .map(|i| {
                        let copies = Self::copies_2(mesh, cells.dim, cells.elements[i].entity);
                        (tags[1][i], copies.len())
                    })
                    .collect()
            }
        };
        let node_tags: Vec<(usize, usize)> = (0..mesh.nodes.len()).map(|i| (i + 1, 1)).collect();
        for (section, arrays, tags) in [
            ("NodeData", point_data, &node_tags),
            ("ElementData", cell_data, &cell_copies),
        ] {
            let count: usize = tags.iter().map(|&(_, copies)| copies).sum();
            for a in arrays {
                writeln!(w, "${section}\n1\n\"{}\"\n1\n0\n3\n0", a.name)?;
                writeln!(w, "{}\n{count}", a.components)?;
                let components = a.components;
                write_records(w, 0..tags.len(), |i, t| {
                    let values = &a.values[i * components..(i + 1) * components];
                    let (first, copies) = tags[i];
                    for tag in first..first + copies {
                        if binary {
                            t.extend_from_slice(&(tag as i32).to_le_bytes());
                            values
                                .iter()
                                .for_each(|v| t.extend_from_slice(&v.to_le_bytes()));
                        } else {
                            push_integer(t, tag as i64);
                            for &v in values {
                                t.push(b' ');
                                push_float(t, v);
                            }
                            t.push(b'\n');
                        }
                    }
                    Ok(())
                })?;
                end_section(w, section, binary)?;
            }
        }
        Ok(())
    }
}

/// `$End<section>`; after binary data, on a line of its own as Gmsh writes it.
fn end_section<W: Write>(w: &mut W, section: &str, binary: bool) -> std::io::Result<()> {
    if binary {
        writeln!(w)?;
    }
    writeln!(w, "$End{section}")
}

/// A header of sizes: `size_t` values in binary, one line of decimals in ASCII.
fn write_sizes<W: Write>(w: &mut W, values: &[usize], binary: bool) -> std::io::Result<()> {
    let mut out = Vec::new();
    if binary {
        values.iter().for_each(|&v| push_size(&mut out, v));
    } else {
        for (k, &v) in values.iter().enumerate() {
            if k > 0 {
                out.push(b' ');
            }
            push_integer(&mut out, v as i64);
        }
        out.push(b'\n');
    }
    w.write_all(&out)
}

/// Appends `n` as a little-endian 8-byte `size_t` (the data size the header declares).
fn push_size(t: &mut Vec<u8>, n: usize) {
    t.extend_from_slice(&(n as u64).to_le_bytes());
}

/// Appends `x y z` and a line break, in shortest round-trip form.
fn push_coordinates(t: &mut Vec<u8>, [x, y, z]: [f64; 3]) {
    push_float(t, x);
    t.push(b' ');
    push_float(t, y);
    t.push(b' ');
    push_float(t, z);
    t.push(b'\n');
}

/// Appends the shortest text that reads back as `x` (as `{:?}` does, faster).
fn push_float(t: &mut Vec<u8>, x: f64) {
    if x.is_finite() {
        t.extend_from_slice(zmij::Buffer::new().format_finite(x).as_bytes());
    } else {
        let _ = write!(t, "{x:?}");
    }
}

/// Appends `n` in decimal.
fn push_integer(t: &mut Vec<u8>, n: i64) {
    t.extend_from_slice(itoa::Buffer::new().format(n).as_bytes());
}

/// Writes the records (text lines or binary) `record(i)` for `i` in `range`, formatted in
/// parallel in blocks of consecutive records and written in order: the bytes of a
/// sequential loop (formatting floats is most of the cost of writing a large mesh). A
/// batch of blocks is written while the next is formatted, into buffers reused from batch
/// to batch.
fn write_records<W: Write + Send>(
    w: &mut W,
    range: Range<usize>,
    record: impl Fn(usize, &mut Vec<u8>) -> std::io::Result<()> + Sync,
) -> std::io::Result<()> {
    const BLOCK: usize = 1 << 13;
    // Blocks formatted at once: bounds the text held in memory.
    const BATCH: usize = 64;
    let blocks: Vec<Range<usize>> = range
        .clone()
        .step_by(BLOCK)
        .map(|s| s..(s + BLOCK).min(range.end))
        .collect();
    let format = |batch: &[Range<usize>], texts: &mut Vec<Vec<u8>>| -> std::io::Result<()> {
        texts.resize_with(batch.len(), Vec::new);
        texts
            .par_iter_mut()
            .zip(batch)
            .try_for_each(|(text, block)| {
                text.clear();
                block.clone().try_for_each(|i| record(i, text))
            })
    };
    let write = |w: &mut W, texts: &[Vec<u8>]| -> std::io::Result<()> {
        texts.iter().try_for_each(|t| w.write_all(t))
    };
    let mut batches = blocks.chunks(BATCH);
    let (mut ready, mut spare) = (Vec::new(), Vec::new());
    if let Some(first) = batches.next() {
        format(first, &mut ready)?;
    }
    for batch in batches {
        let (written, formatted) = rayon::join(|| write(w, &ready), || format(batch, &mut spare));
        written?;
        formatted?;
        std::mem::swap(&mut ready, &mut spare);
    }
    write(w, &ready)
}

#[cfg(test)]
#[path = "tests/msh_write.rs"]
mod tests;
