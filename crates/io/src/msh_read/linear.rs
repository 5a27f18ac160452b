//! The linear-mesh reader ([`read_msh`], [`parse_msh`]): the [`LinearMesh`] assembled from
//! what the sections held (see the module documentation of [`super`]), then validated.

use std::path::Path;

use hocurve_mesh::LinearMesh;

use super::failure::R;
use super::parser::{take_dim, Parser};
use super::physicals::physical_groups;
use crate::error::IoError;

/// Reads a Gmsh mesh file (MSH 4.1 or 2.2, ASCII or binary).
pub fn read_msh(path: &Path) -> Result<LinearMesh, IoError> {
    let bytes = std::fs::read(path).map_err(|source| IoError::Os {
        path: path.to_path_buf(),
        source,
    })?;
    parse_msh(&bytes, path)
}

/// Same from bytes already in memory; `path` only names the file in errors.
pub fn parse_msh(bytes: &[u8], path: &Path) -> Result<LinearMesh, IoError> {
    let mesh = Parser::new(bytes, false)
        .parse()
        .map_err(|e| IoError::Malformed {
            path: path.to_path_buf(),
            location: e.location,
            message: e.message,
        })?;
    mesh.validate().map_err(|source| IoError::Mesh {
        path: path.to_path_buf(),
        source,
    })?;
    Ok(mesh)
}

impl Parser<'_> {
    /// The linear mesh of the whole file.
    fn parse(mut self) -> R<LinearMesh> {
        self.read_sections()?;
        self.finish()
    }

    /// The linear mesh of what was read: cells of the highest dimension present, facets one
    /// dimension lower, with their tags and the physical groups.
    fn finish(mut self) -> R<LinearMesh> {
        let dim = self.cell_dimension(
            (1..=3).rev(),
            "the file has no line, surface or volume elements",
        )?;
        Ok(LinearMesh {
            dim,
            vertices: self.vertices,
            cells: take_dim(&mut self.by_dim, dim),
            facets: take_dim(&mut self.by_dim, dim - 1),
            physical_groups: physical_groups(self.names, &self.entity_physicals),
            entity_physicals: self.entity_physicals,
            vertex_tags: self.node_tags,
            cell_tags: take_dim(&mut self.element_tags, dim),
            facet_tags: take_dim(&mut self.element_tags, dim - 1),
        })
    }
}
