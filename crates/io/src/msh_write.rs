//! Gmsh MSH 4.1 ASCII writer for high-order meshes.
//!
//! Elements are Gmsh's complete order-p elements (`MSH_TRI_10`, `MSH_TET_35`,
//! `MSH_HEX_125`, …), their nodes in Gmsh's order (see [`crate::ordering`]); the declared
//! facets are written too, at the same order, on their own entities. What is written:
//! - `$PhysicalNames`: the physical groups that have a name (unnamed groups live on in the
//!   entities' physical tags);
//! - `$Entities`: one curve/surface/volume per distinct (dimension, entity tag) of the cells
//!   and facets, with its physical tags and the bounding box of its elements' nodes, no
//!   bounding entities;
//! - `$Nodes`: node tags 1..N in the mesh's node order, in that order in the file; each node
//!   is classified on the lowest-dimensional entity (then smallest tag) among those whose
//!   elements use it, as Gmsh itself classifies boundary nodes on the boundary surface; a
//!   block per run of consecutive nodes on the same entity (an entity may have several);
//! - `$Elements`: facets then cells, in their order in the mesh, one block per run of
//!   consecutive elements with the same entity and type; element tags 1, 2, ….
//!
//! - `$NodeData` / `$ElementData` ([`write_msh_with`]): one view per data array (scalar or
//!   3-vector; string tag its name, real tag time 0, integer tags time step 0, the number
//!   of components and of values), values per node tag and per cell's element tag.
//!
//! Coordinates and data are written in Rust's shortest round-trip form (`{:?}`), so reading
//! the file back gives bitwise the same values. Same input, same bytes.

use std::collections::BTreeMap;
use std::fmt::Write as _;
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
    write_atomically(path, |w| {
        plan.write(w, mesh)
            .and_then(|()| plan.write_data(w, mesh, point_data, cell_data))
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

    fn write<W: Write + Send>(&self, w: &mut W, mesh: &HighOrderMesh) -> std::io::Result<()> {
        writeln!(w, "$MeshFormat\n4.1 0 8\n$EndMeshFormat")?;

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

        writeln!(w, "$Entities")?;
        let count = |d: usize| self.entities.iter().filter(|((e, _), _)| *e == d).count();
        writeln!(w, "0 {} {} {}", count(1), count(2), count(3))?;
        for ((dim, tag), b) in &self.entities {
            write!(w, "{tag}")?;
            for v in b {
                write!(w, " {v:?}")?;
            }
            let physicals = mesh.physical_tags(*dim, *tag);
            write!(w, " {}", physicals.len())?;
            for t in physicals {
                write!(w, " {t}")?;
            }
            writeln!(w, " 0")?;
        }
        writeln!(w, "$EndEntities")?;

        writeln!(w, "$Nodes")?;
        // Blocks are runs of consecutive nodes classified on the same entity, so that node
        // tags 1..N appear in increasing order (readers that number nodes by appearance get
        // the mesh's own numbering back); an entity may own several blocks.
        let mut runs = Vec::new();
        let mut start = 0;
        for i in 1..=self.node_entity.len() {
            if i == self.node_entity.len() || self.node_entity[i] != self.node_entity[start] {
                runs.push((start, i));
                start = i;
            }
        }
        let n = mesh.nodes.len();
        writeln!(w, "{} {n} {} {n}", runs.len(), n.min(1))?;
        for (start, end) in runs {
            let ((dim, tag), _) = self.entities[self.node_entity[start]];
            writeln!(w, "{dim} {tag} 0 {}", end - start)?;
            write_lines(w, start..end, |i, t| {
                push_integer(t, i + 1);
                t.push('\n');
                Ok(())
            })?;
            write_lines(w, start..end, |i, t| {
                let [x, y, z] = mesh.nodes[i];
                push_float(t, x);
                t.push(' ');
                push_float(t, y);
                t.push(' ');
                push_float(t, z);
                t.push('\n');
                Ok(())
            })?;
        }
        writeln!(w, "$EndNodes")?;

        writeln!(w, "$Elements")?;
        // Runs of consecutive elements with the same (entity, shape).
        let mut runs = Vec::new();
        for (g, group) in self.groups.iter().enumerate() {
            let mut start = 0;
            for i in 1..=group.elements.len() {
                let split = i == group.elements.len()
                    || group.elements[i].entity != group.elements[start].entity
                    || group.shapes[i] != group.shapes[start];
                if split {
                    runs.push((g, start, i));
                    start = i;
                }
            }
        }
        let total: usize = self.groups.iter().map(|g| g.elements.len()).sum();
        writeln!(w, "{} {total} {} {total}", runs.len(), total.min(1))?;
        let mut tag = 0usize;
        for (g, start, end) in runs {
            let group = &self.groups[g];
            let shape = group.shapes[start];
            let (gmsh_type, perm) = &self.types[&shape];
            let entity = group.elements[start].entity;
            writeln!(w, "{} {entity} {gmsh_type} {}", group.dim, end - start)?;
            let first_tag = tag + 1 - start;
            write_lines(w, start..end, |i, t| {
                push_integer(t, first_tag + i);
                for &k in perm {
                    t.push(' ');
                    push_integer(t, group.elements[i].nodes[k] as usize + 1);
                }
                t.push('\n');
                Ok(())
            })?;
            tag += end - start;
        }
        writeln!(w, "$EndElements")?;
        Ok(())
    }

    /// The `$NodeData` and `$ElementData` views (arrays already checked).
    fn write_data<W: Write + Send>(
        &self,
        w: &mut W,
        mesh: &HighOrderMesh,
        point_data: &[DataArray],
        cell_data: &[DataArray],
    ) -> std::io::Result<()> {
        // Element tags: facets 1..=F, then cells F+1.. (the order of `write`).
        let first_cell_tag = mesh.facets.len() + 1;
        for (section, arrays, count, first_tag) in [
            ("NodeData", point_data, mesh.nodes.len(), 1),
            ("ElementData", cell_data, mesh.cells.len(), first_cell_tag),
        ] {
            for a in arrays {
                writeln!(w, "${section}\n1\n\"{}\"\n1\n0\n3\n0", a.name)?;
                writeln!(w, "{}\n{count}", a.components)?;
                let components = a.components;
                write_lines(w, 0..a.values.len() / components, |i, t| {
                    push_integer(t, first_tag + i);
                    for &v in &a.values[i * components..(i + 1) * components] {
                        t.push(' ');
                        push_float(t, v);
                    }
                    t.push('\n');
                    Ok(())
                })?;
                writeln!(w, "$End{section}")?;
            }
        }
        Ok(())
    }
}

/// Appends the shortest text that reads back as `x` (as `{:?}` does, faster).
fn push_float(t: &mut String, x: f64) {
    if x.is_finite() {
        t.push_str(zmij::Buffer::new().format_finite(x));
    } else {
        let _ = write!(t, "{x:?}");
    }
}

/// Appends `n` in decimal.
fn push_integer(t: &mut String, n: usize) {
    t.push_str(itoa::Buffer::new().format(n));
}

/// Writes the lines `line(i)` for `i` in `range`, formatted in parallel in blocks of
/// consecutive lines and written in order: the bytes of a sequential loop (formatting
/// floats is most of the cost of writing a large mesh). A batch of blocks is written while
/// the next is formatted, into buffers reused from batch to batch.
fn write_lines<W: Write + Send>(
    w: &mut W,
    range: Range<usize>,
    line: impl Fn(usize, &mut String) -> std::fmt::Result + Sync,
) -> std::io::Result<()> {
    const BLOCK: usize = 1 << 13;
    // Blocks formatted at once: bounds the text held in memory.
    const BATCH: usize = 64;
    let blocks: Vec<Range<usize>> = range
        .clone()
        .step_by(BLOCK)
        .map(|s| s..(s + BLOCK).min(range.end))
        .collect();
    let format = |batch: &[Range<usize>], texts: &mut Vec<String>| -> std::io::Result<()> {
        texts.resize_with(batch.len(), String::new);
        texts
            .par_iter_mut()
            .zip(batch)
            .try_for_each(|(text, block)| {
                text.clear();
                block.clone().try_for_each(|i| line(i, text))
            })
            .map_err(|_| std::io::Error::other("formatting a mesh line failed"))
    };
    let write = |w: &mut W, texts: &[String]| -> std::io::Result<()> {
        texts.iter().try_for_each(|t| w.write_all(t.as_bytes()))
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
