//! The walk through an MSH file: `$MeshFormat` first, then the sections in any order, each
//! handed to its parser ([`super::mesh_format`], [`super::physicals`], [`super::nodes`],
//! [`super::elements`]); sections hocurve does not need are skipped.

use super::failure::{fail, in_section, R};
use super::node_index::NodeIndex;
use super::parser::{Parser, Version};
use super::tokens::show;
use crate::error::Location;

impl Parser<'_> {
    /// Reads every section of the file.
    pub(super) fn read_sections(&mut self) -> R<()> {
        match self.input.next_line() {
            None => {
                return fail(
                    Location::EndOfFile,
                    "the file is empty (expected $MeshFormat)",
                )
            }
            Some((_, b"$MeshFormat", _)) => {}
            Some((loc, text, _)) => {
                let hint = if text == b"$NOD" || text == b"$NOE" {
                    " (MSH 1.0 files are not supported; re-save the mesh as MSH 4.1)"
                } else {
                    ""
                };
                return fail(
                    loc,
                    format!(
                        "expected $MeshFormat at the start of a Gmsh MSH file, found {}{hint}",
                        show(text)
                    ),
                );
            }
        }
        self.mesh_format()?;
        while let Some((loc, text, _)) = self.input.next_line() {
            let Some(name) = text.strip_prefix(b"$") else {
                return fail(
                    loc,
                    format!(
                        "expected a section header such as $Nodes or $Elements, found {}",
                        show(text)
                    ),
                );
            };
            match name {
                b"MeshFormat" => return fail(loc, "a second $MeshFormat section"),
                b"PhysicalNames" => self
                    .physical_names()
                    .map_err(|e| in_section(e, "PhysicalNames", "", None, 0))?,
                b"Entities" if self.version == Version::V41 => self
                    .entities()
                    .map_err(|e| in_section(e, "Entities", "", None, 0))?,
                b"PartitionedEntities" => {
                    return fail(
                        loc,
                        "partitioned meshes are not supported (found $PartitionedEntities); \
                         save the mesh without partitions",
                    )
                }
                b"Nodes" => {
                    if self.nodes.is_some() {
                        return fail(loc, "a second $Nodes section (only one is supported)");
                    }
                    let mut announced = None;
                    let r = match self.version {
                        Version::V41 => self.nodes_v41(&mut announced),
                        Version::V2 => self.nodes_v2(&mut announced),
                    };
                    let read = self.vertices.len() as u64;
                    r.map_err(|e| in_section(e, "Nodes", "nodes", announced, read))?;
                    self.nodes = Some(NodeIndex::new(&self.node_tags, loc)?);
                }
                b"Elements" => {
                    if self.nodes.is_none() {
                        return fail(loc, "$Elements comes before $Nodes");
                    }
                    if self.have_elements {
                        return fail(loc, "a second $Elements section (only one is supported)");
                    }
                    self.have_elements = true;
                    let mut announced = None;
                    let mut read = 0u64;
                    let r = match self.version {
                        Version::V41 => self.elements_v41(&mut announced, &mut read),
                        Version::V2 => self.elements_v2(&mut announced, &mut read),
                    };
                    r.map_err(|e| in_section(e, "Elements", "elements", announced, read))?;
                }
                _ if name.starts_with(b"End") => {
                    return fail(
                        loc,
                        format!("{} without a matching section start", show(text)),
                    )
                }
                _ => self.input.skip_section(name, loc)?,
            }
        }
        Ok(())
    }
}
