//! Physical groups: `$PhysicalNames` (named groups), the physical tags of the geometric
//! entities in `$Entities` (MSH 4.1), and the list of groups a mesh gets from them.

use std::collections::BTreeMap;

use hocurve_mesh::PhysicalGroup;

use super::failure::{fail, fewer_than_announced, R};
use super::parser::Parser;
use super::tokens::show;

impl Parser<'_> {
    /// `$PhysicalNames`: the dimension, tag and name of each named physical group.
    pub(super) fn physical_names(&mut self) -> R<()> {
        let input = &mut self.input;
        input.begin_text(|| "the number of physical names".into())?;
        let n = input.size(|| "the number of physical names".into())?;
        input.end_record(|| "the number of physical names".into())?;
        for i in 0..n {
            // $PhysicalNames is text, also in binary files.
            if let Some(loc) = input.peek_dollar() {
                return fail(
                    loc,
                    fewer_than_announced("physical name", "PhysicalNames", n, i),
                );
            }
            input.begin_text(|| format!("physical name {} of {n}", i + 1))?;
            let dim = input.int(|| "the dimension of a physical group".into())?;
            let dim = match usize::try_from(dim) {
                Ok(d) if d <= 3 => d,
                _ => {
                    return fail(
                        input.rec_location(),
                        format!("expected a physical group dimension 0 to 3, found {dim}"),
                    )
                }
            };
            let tag = input.int32(|| "the tag of a physical group".to_string())?;
            let rest = input.rest_of_record();
            let name = match rest {
                [] => &[][..],
                [b'"', inner @ ..] => match inner.iter().rposition(|&c| c == b'"') {
                    Some(k) => &inner[..k],
                    None => {
                        return fail(
                            input.rec_location(),
                            format!("unterminated quoted physical name {}", show(rest)),
                        )
                    }
                },
                other => other,
            };
            self.names.push(PhysicalGroup {
                dim,
                tag,
                name: String::from_utf8_lossy(name).into_owned(),
            });
        }
        input.expect_end("PhysicalNames", || {
            format!(" after the {n} names announced in the $PhysicalNames header")
        })
    }

    /// `$Entities` (MSH 4.1): the physical tags of each point, curve, surface and volume;
    /// coordinates and bounding entities are read past.
    pub(super) fn entities(&mut self) -> R<()> {
        let input = &mut self.input;
        input.begin(|| "the entity counts (points, curves, surfaces, volumes)".into())?;
        let mut counts = [0u64; 4];
        for (d, c) in counts.iter_mut().enumerate() {
            *c = input.size(|| format!("the number of {}s", entity_word(d)))?;
        }
        input.end_record(|| "the four entity counts".into())?;
        for (dim, &count) in counts.iter().enumerate() {
            let word = entity_word(dim);
            for i in 0..count {
                input.begin_announced(
                    || {
                        format!(
                            "$Entities header announces {count} {word}s but the section holds {i}"
                        )
                    },
                    || format!("{word} {} of {count}", i + 1),
                )?;
                let tag = input.int32(|| format!("the tag of {word} {} of {count}", i + 1))?;
                let ncoords = if dim == 0 { 3 } else { 6 };
                for _ in 0..ncoords {
                    input.float(|| format!("the coordinates of {word} {tag}"))?;
                }
                let np = input.size(|| format!("the number of physical tags of {word} {tag}"))?;
                input.check_room(np, 4, || format!("{word} {tag}'s physical tags"))?;
                let mut phys = Vec::new();
                for _ in 0..np {
                    phys.push(input.int32(|| format!("a physical tag of {word} {tag}"))?);
                }
                if dim > 0 {
                    let nb = input
                        .size(|| format!("the number of bounding entities of {word} {tag}"))?;
                    input.check_room(nb, 4, || format!("{word} {tag}'s bounding entities"))?;
                    for _ in 0..nb {
                        input.int32(|| format!("a bounding entity of {word} {tag}"))?;
                    }
                }
                input.end_record(|| format!("the description of {word} {tag}"))?;
                if !phys.is_empty() {
                    let e = self.entity_physicals.entry((dim, tag)).or_default();
                    e.extend(phys);
                    e.sort_unstable();
                    e.dedup();
                }
            }
        }
        input.expect_end("Entities", || {
            format!(
                " after the {} entities announced in the $Entities header",
                counts.iter().fold(0u64, |a, &c| a.saturating_add(c))
            )
        })
    }
}

/// The name of an entity of dimension `dim`, for messages.
fn entity_word(dim: usize) -> &'static str {
    match dim {
        0 => "point",
        1 => "curve",
        2 => "surface",
        _ => "volume",
    }
}

/// Physical groups: the named ones plus every physical tag used but not named.
pub(super) fn physical_groups(
    names: Vec<PhysicalGroup>,
    entity_physicals: &BTreeMap<(usize, i32), Vec<i32>>,
) -> Vec<PhysicalGroup> {
    let mut groups: BTreeMap<(usize, i32), String> = BTreeMap::new();
    for g in names {
        groups.entry((g.dim, g.tag)).or_insert(g.name);
    }
    for (&(d, _), tags) in entity_physicals {
        for &t in tags {
            groups.entry((d, t)).or_default();
        }
    }
    groups
        .into_iter()
        .map(|((dim, tag), name)| PhysicalGroup { dim, tag, name })
        .collect()
}
