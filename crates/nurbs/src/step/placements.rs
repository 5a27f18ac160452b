//! Where the parts of an assembly lie: each representation's placement in the model, from
//! the representation relationships (with an `ITEM_DEFINED_TRANSFORMATION`: the child's
//! frame `item_1` carried onto `item_2` in the parent, as OpenCASCADE reads them; without
//! one: the same space), one per occurrence, so that a part used twice gives its faces twice.

use std::collections::{BTreeMap, BTreeSet};

use super::convert::{Converter, Frame, MAX_DEPTH};
use super::error::StepError;
use super::parse::{StepInstance, StepRecord, StepValue};
use crate::iges::affine::{compose, Affine, IDENTITY};

/// More occurrences than this of one item (nested instancing) are refused.
const MAX_OCCURRENCES: usize = 4096;

/// The placements of faces, edges and curves: their representation's maps into the model.
#[derive(Debug, Default)]
pub(super) struct Placements {
    /// Item id → its maps (absent: the identity).
    by_item: BTreeMap<u64, Vec<Affine>>,
}

impl Placements {
    /// The maps of item `id` into the model (the identity when it is in no placed part).
    pub(super) fn of(&self, id: u64) -> Vec<Affine> {
        self.by_item
            .get(&id)
            .cloned()
            .unwrap_or_else(|| vec![IDENTITY])
    }
}

/// The affine map carrying frame `a` onto frame `b`: x ↦ B Aᵀ (x − a.origin) + b.origin.
fn frame_to_frame(a: &Frame, b: &Frame) -> Affine {
    let mut t = [[0.0; 4]; 3];
    for i in 0..3 {
        for j in 0..3 {
            t[i][j] = b.x[i] * a.x[j] + b.y[i] * a.y[j] + b.z[i] * a.z[j];
        }
    }
    for i in 0..3 {
        t[i][3] = b.origin[i] - (0..3).map(|j| t[i][j] * a.origin[j]).sum::<f64>();
    }
    t
}

/// Union-find root of `x`.
fn root(classes: &mut BTreeMap<u64, u64>, x: u64) -> u64 {
    let mut r = x;
    while let Some(&p) = classes.get(&r) {
        if p == r {
            break;
        }
        r = p;
    }
    classes.insert(x, r);
    r
}

impl Converter<'_> {
    /// The placements of every face, edge and curve of the file's representations.
    pub(super) fn placements(&self) -> Result<Placements, StepError> {
        // Representations linked without a transformation share one space (a class).
        let mut classes: BTreeMap<u64, u64> = BTreeMap::new();
        let mut placed: Vec<(u64, u64, Affine, &StepInstance)> = Vec::new();
        for i in self.file.instances.values() {
            // Its subtypes name the same two representations: a shape representation
            // relationship written on its own (`SHAPE_REPRESENTATION_RELATIONSHIP('', '',
            // part, brep)`, as most CAD systems link a part to its B-rep) carries them in
            // its own record; in a complex instance the supertype's record does.
            let Some(r) = i.record("REPRESENTATION_RELATIONSHIP").or_else(|| {
                i.records.iter().find(|r| {
                    r.name.ends_with("REPRESENTATION_RELATIONSHIP") && r.params.len() >= 4
                })
            }) else {
                continue;
            };
            let (Some(child), Some(parent)) = (
                r.params.get(2).and_then(StepValue::reference),
                r.params.get(3).and_then(StepValue::reference),
            ) else {
                return Err(self.fail(
                    i,
                    "a representation relationship without its two representations",
                ));
            };
            match i.record("REPRESENTATION_RELATIONSHIP_WITH_TRANSFORMATION") {
                Some(w) => {
                    let t = w
                        .params
                        .first()
                        .ok_or_else(|| self.fail(i, "a relationship without its transformation"))?;
                    let item = self.get(t, i)?;
                    let Some(idt) = item.record("ITEM_DEFINED_TRANSFORMATION") else {
                        return Err(self.unsupported(item, " (as a placement transformation)"));
                    };
                    if idt.params.len() < 4 {
                        return Err(
                            self.fail(item, "ITEM_DEFINED_TRANSFORMATION needs two placements")
                        );
                    }
                    // Each placement in the units of its own representation.
                    let in_units_of = |rep: u64| -> Result<Converter<'_>, StepError> {
                        let length = match self.file.instances.get(&rep) {
                            Some(r) => self.representation_length(r)?,
                            None => self.length,
                        };
                        Ok(Converter {
                            file: self.file,
                            length,
                            angle: self.angle,
                        })
                    };
                    let a = in_units_of(child)?.placement(&idt.params[2], item)?;
                    let b = in_units_of(parent)?.placement(&idt.params[3], item)?;
                    placed.push((child, parent, frame_to_frame(&a, &b), i));
                }
                None => {
                    let (x, y) = (root(&mut classes, child), root(&mut classes, parent));
                    classes.insert(x, y);
                }
            }
        }
        let mut parents: BTreeMap<u64, Vec<(u64, Affine)>> = BTreeMap::new();
        for &(child, parent, t, _) in &placed {
            let (c, p) = (root(&mut classes, child), root(&mut classes, parent));
            parents.entry(c).or_default().push((p, t));
        }
        // Each class's maps into the model: composed up to the classes with no parent.
        let mut memo: BTreeMap<u64, Vec<Affine>> = BTreeMap::new();
        let mut by_item: BTreeMap<u64, BTreeSet<u64>> = BTreeMap::new();
        for i in self.file.instances.values() {
            let Some(items) = self.representation_items(i) else {
                continue;
            };
            let class = root(&mut classes, i.id);
            for item in items {
                self.collect_items(item, i, 0, &mut |id| {
                    by_item.entry(id).or_default().insert(class);
                })?;
            }
        }
        let mut out = Placements::default();
        if placed.is_empty() {
            return Ok(out);
        }
        for (id, classes_of) in by_item {
            // A placed part's B-rep is often also the item of a representation outside the
            // assembly (a shape aspect's "solid data", Pro/E): that is not an occurrence.
            let placed_somewhere = classes_of.iter().any(|c| parents.contains_key(c));
            let mut maps = Vec::new();
            for class in classes_of {
                if placed_somewhere && !parents.contains_key(&class) {
                    continue;
                }
                for t in self.class_maps(class, &parents, &mut memo, 0)? {
                    if !maps.contains(&t) {
                        maps.push(t);
                    }
                }
            }
            if maps.len() > MAX_OCCURRENCES {
                return Err(StepError::TooManyOccurrences {
                    id,
                    limit: MAX_OCCURRENCES,
                });
            }
            out.by_item.insert(id, maps);
        }
        Ok(out)
    }

    /// The record of a representation (`NAME_REPRESENTATION(name, items, context)`).
    fn representation_record<'i>(&self, i: &'i StepInstance) -> Option<&'i StepRecord> {
        i.records
            .iter()
            .find(|r| r.name.ends_with("_REPRESENTATION") || r.name == "REPRESENTATION")
            .filter(|r| r.name != "SHAPE_DEFINITION_REPRESENTATION")
    }

    /// The items of a representation.
    fn representation_items<'i>(&self, i: &'i StepInstance) -> Option<&'i [StepValue]> {
        self.representation_record(i)
            .and_then(|r| r.params.get(1))
            .and_then(StepValue::list)
    }

    /// The context of a representation, where its units are assigned.
    pub(super) fn representation_context(&self, i: &StepInstance) -> Option<&StepInstance> {
        self.representation_record(i)
            .and_then(|r| r.params.get(2))
            .and_then(StepValue::reference)
            .and_then(|id| self.file.instances.get(&id))
    }

    /// The contexts of the representations that hold faces, edges or curves, each once.
    pub(super) fn geometry_contexts(&self) -> Result<Vec<&StepInstance>, StepError> {
        let mut out: Vec<&StepInstance> = Vec::new();
        for i in self.file.instances.values() {
            let Some(items) = self.representation_items(i) else {
                continue;
            };
            let mut holds = false;
            for item in items {
                self.collect_items(item, i, 0, &mut |_| holds = true)?;
            }
            if let (true, Some(c)) = (holds, self.representation_context(i)) {
                if !out.iter().any(|x| x.id == c.id) {
                    out.push(c);
                }
            }
        }
        Ok(out)
    }

    /// Calls `found` with every face, edge and curve under `v` (through solids, shells,
    /// face bounds, edge loops and curve sets).
    fn collect_items(
        &self,
        v: &StepValue,
        parent: &StepInstance,
        depth: usize,
        found: &mut dyn FnMut(u64),
    ) -> Result<(), StepError> {
        if depth > MAX_DEPTH {
            return Err(StepError::TooDeep {
                id: parent.id,
                line: parent.line,
                limit: MAX_DEPTH,
            });
        }
        let Some(id) = v.reference() else {
            return Ok(());
        };
        let Some(i) = self.file.instances.get(&id) else {
            return Ok(()); // reported where the item is converted
        };
        let descend = match i.type_name().as_str() {
            "ADVANCED_FACE" | "FACE_SURFACE" | "EDGE_CURVE" | "TRIMMED_CURVE" => {
                found(id);
                !matches!(i.type_name().as_str(), "EDGE_CURVE" | "TRIMMED_CURVE")
            }
            "MAPPED_ITEM" => {
                return Err(self.unsupported(i, " (a mapped item: export the assembly flattened)"))
            }
            "MANIFOLD_SOLID_BREP"
            | "BREP_WITH_VOIDS"
            | "FACETED_BREP"
            | "CLOSED_SHELL"
            | "OPEN_SHELL"
            | "ORIENTED_CLOSED_SHELL"
            | "SHELL_BASED_SURFACE_MODEL"
            | "FACE_BASED_SURFACE_MODEL"
            | "CONNECTED_FACE_SET"
            | "FACE_BOUND"
            | "FACE_OUTER_BOUND"
            | "EDGE_LOOP"
            | "ORIENTED_EDGE"
            | "GEOMETRIC_CURVE_SET"
            | "GEOMETRIC_SET" => true,
            _ => false,
        };
        if descend {
            for p in &i.records[0].params {
                match p {
                    StepValue::Reference(_) => self.collect_items(p, i, depth + 1, found)?,
                    StepValue::List(items) => {
                        for x in items {
                            self.collect_items(x, i, depth + 1, found)?;
                        }
                    }
                    _ => {}
                }
            }
        }
        Ok(())
    }

    /// The maps of a class of representations into the model.
    fn class_maps(
        &self,
        class: u64,
        parents: &BTreeMap<u64, Vec<(u64, Affine)>>,
        memo: &mut BTreeMap<u64, Vec<Affine>>,
        depth: usize,
    ) -> Result<Vec<Affine>, StepError> {
        if let Some(maps) = memo.get(&class) {
            return Ok(maps.clone());
        }
        let Some(ups) = parents.get(&class) else {
            return Ok(vec![IDENTITY]);
        };
        if depth > MAX_DEPTH {
            return Err(StepError::TooDeep {
                id: class,
                line: self.file.instances.get(&class).map_or(0, |i| i.line),
                limit: MAX_DEPTH,
            });
        }
        let mut maps = Vec::new();
        for &(parent, t) in ups {
            for w in self.class_maps(parent, parents, memo, depth + 1)? {
                maps.push(compose(&w, &t));
                if maps.len() > MAX_OCCURRENCES {
                    return Err(StepError::TooManyOccurrences {
                        id: class,
                        limit: MAX_OCCURRENCES,
                    });
                }
            }
        }
        memo.insert(class, maps.clone());
        Ok(maps)
    }
}
