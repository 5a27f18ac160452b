//! The checks on a parsed file's pointers that make converting it terminate: parameter
//! pointers lead to existing entities, references form no cycle and nest at most
//! [`MAX_NESTING`] deep, transformation pointers lead to chains of 124 matrices.

use super::entities::EntityData;
use super::error::{IgesError, ReferenceKind};
use super::limits::MAX_NESTING;
use super::model::{IgesEntity, IgesModel};
use super::param_reader::Reference;

impl IgesModel {
    /// Checks that the entities' references (composite members, trimmed surfaces' surfaces
    /// and boundaries, curves on surfaces, revolutions' axis and generatrix, ...) form no
    /// cycle and nest at most [`MAX_NESTING`] deep, so that converting them terminates with
    /// a bounded stack. Depth-first with an explicit stack: a file cannot drive it into a
    /// stack overflow. References to missing DEs are left to the conversion's errors.
    pub fn check_references(&self) -> Result<(), IgesError> {
        const NEW: u8 = 0;
        const OPEN: u8 = 1;
        const DONE: u8 = 2;
        let index = |de: u32| -> Option<usize> { self.entity(de).map(|_| (de as usize - 1) / 2) };
        let children: Vec<Vec<usize>> = self
            .entities
            .iter()
            .map(|e| e.kind.references().into_iter().filter_map(index).collect())
            .collect();
        let mut state = vec![NEW; self.entities.len()];
        let mut depth = vec![0usize; self.entities.len()];
        for root in 0..self.entities.len() {
            if state[root] != NEW {
                continue;
            }
            // (entity, next child to visit)
            let mut stack: Vec<(usize, usize)> = vec![(root, 0)];
            state[root] = OPEN;
            while let Some(top) = stack.last_mut() {
                let node = top.0;
                if let Some(&child) = children[node].get(top.1) {
                    top.1 += 1;
                    match state[child] {
                        NEW => {
                            state[child] = OPEN;
                            stack.push((child, 0));
                        }
                        OPEN => return Err(self.cycle_error(&stack, child)),
                        _ => {}
                    }
                    continue;
                }
                let d = 1 + children[node].iter().map(|&c| depth[c]).max().unwrap_or(0);
                if d > MAX_NESTING {
                    return Err(nesting_error(
                        &self.entities[node],
                        ReferenceKind::Parameter,
                    ));
                }
                depth[node] = d;
                state[node] = DONE;
                stack.pop();
            }
        }
        Ok(())
    }

    /// The error for the cycle closed by a reference to `back` from the top of `stack`.
    fn cycle_error(&self, stack: &[(usize, usize)], back: usize) -> IgesError {
        let path: Vec<usize> = stack.iter().map(|&(n, _)| n).collect();
        cycle_error(self, &path, back, ReferenceKind::Parameter)
    }
}

/// Checks pointers: parameters point to existing entities, transformation pointers to 124
/// entities without cycles.
pub(super) fn validate(
    model: &IgesModel,
    references: &[(Reference, u32, i32)],
) -> Result<(), IgesError> {
    for (r, de, entity_type) in references {
        if model.entity(r.pointer).is_none() {
            return Err(IgesError::Parameter {
                line: r.line,
                de: *de,
                entity_type: *entity_type,
                index: r.index,
                name: r.name,
                expected: "a pointer to an existing Directory Entry (odd, in range)",
                found: r.pointer.to_string(),
            });
        }
    }
    check_transforms(model)
}

/// Checks the transformation pointers (DE field 7): each leads to a 124 matrix, whose own
/// field 7 leads to another or ends, without a cycle and at most [`MAX_NESTING`] matrices
/// long. Every entity is walked once (chain lengths are remembered), so a file of many long
/// chains costs linear time.
fn check_transforms(model: &IgesModel) -> Result<(), IgesError> {
    let n = model.entities.len();
    // matrices after an entity, `None` until known
    let mut length: Vec<Option<usize>> = vec![None; n];
    let mut on_path = vec![false; n];
    for start in 0..n {
        let mut path: Vec<usize> = Vec::new();
        let mut node = start;
        // walk until an entity whose chain length is known or that has no matrix
        let mut tail = loop {
            if let Some(known) = length[node] {
                break known;
            }
            path.push(node);
            on_path[node] = true;
            let e = &model.entities[node];
            let Some(t) = e.transform else {
                break 0;
            };
            let target = transform_target(model, e, t)?;
            if on_path[target] {
                return Err(cycle_error(
                    model,
                    &path,
                    target,
                    ReferenceKind::Transformation,
                ));
            }
            node = target;
        };
        // the walked entities have the chain below them plus their own matrix pointer
        for &k in path.iter().rev() {
            on_path[k] = false;
            tail += usize::from(model.entities[k].transform.is_some());
            if tail > MAX_NESTING {
                return Err(nesting_error(
                    &model.entities[k],
                    ReferenceKind::Transformation,
                ));
            }
            length[k] = Some(tail);
        }
    }
    Ok(())
}

/// The index of the 124 entity that `e`'s field 7 (`t`) points to.
fn transform_target(model: &IgesModel, e: &IgesEntity, t: u32) -> Result<usize, IgesError> {
    match model.entity(t) {
        Some(x) if matches!(x.kind, EntityData::TransformationMatrix { .. }) => {
            Ok((t as usize - 1) / 2)
        }
        other => Err(IgesError::Syntax {
            line: e.line,
            expected: format!(
                "DE {} field 7: a pointer to a 124 transformation matrix or 0",
                e.de
            ),
            found: match other {
                Some(x) => format!("DE {t} of entity type {}", x.type_number()),
                None => format!("DE {t}, which does not exist"),
            },
        }),
    }
}

/// The error for `e`, whose references of kind `via` nest deeper than [`MAX_NESTING`].
fn nesting_error(e: &IgesEntity, via: ReferenceKind) -> IgesError {
    IgesError::NestingTooDeep {
        line: e.line,
        de: e.de,
        entity_type: e.type_number(),
        max: MAX_NESTING,
        via,
    }
}

/// The error for a cycle: `path` (entity indices) ends with an entity pointing back to
/// `back`, which is on it. Names the cycle from `back` round to itself.
fn cycle_error(model: &IgesModel, path: &[usize], back: usize, via: ReferenceKind) -> IgesError {
    let start = path.iter().position(|&n| n == back).unwrap_or(0);
    let des: Vec<String> = path[start..]
        .iter()
        .chain(std::iter::once(&back))
        .map(|&n| model.entities[n].de.to_string())
        .collect();
    let e = &model.entities[back];
    IgesError::ReferenceCycle {
        line: e.line,
        de: e.de,
        entity_type: e.type_number(),
        cycle: des.join(" -> "),
        via,
    }
}
