//! The bundled demonstration cases, compiled into the library so that `hocurve demo` works
//! from any directory and after `cargo install`: the paper's NACA0012 airfoil (Sect. 5.1,
//! p = 5) and a sphere in a box (p = 4), each a linear Gmsh mesh with its JSON geometry.

use std::path::Path;

use hocurve_geodesic::AssociationRule;
use hocurve_io::IoError;
use hocurve_mesh::LinearMesh;
use hocurve_nurbs::{parse_geometry_json, GeometryInputError, GeometryModel};

/// A bundled case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Demo {
    /// The unit-radius sphere inside the box [−3, 3]³, tetrahedra, curved at p = 4.
    Sphere,
    /// The NACA0012 airfoil in a circular far field, triangles, curved at p = 5 (the paper's
    /// Sect. 5.1 example).
    Naca0012,
}

/// Errors reading a bundled case (only if the bundled files were corrupted at build time).
#[derive(Debug, thiserror::Error)]
pub enum DemoError {
    /// The bundled mesh does not parse.
    #[error(transparent)]
    Mesh(#[from] IoError),
    /// The bundled geometry does not parse.
    #[error(transparent)]
    Geometry(#[from] GeometryInputError),
}

impl Demo {
    /// Every bundled case.
    pub const ALL: [Demo; 2] = [Demo::Sphere, Demo::Naca0012];

    /// The case's name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Demo::Sphere => "sphere",
            Demo::Naca0012 => "naca0012",
        }
    }

    /// The order the case is curved to.
    pub fn order(self) -> usize {
        match self {
            Demo::Sphere => 4,
            Demo::Naca0012 => 5,
        }
    }

    /// The bundled linear mesh (Gmsh MSH).
    pub fn mesh_bytes(self) -> &'static [u8] {
        match self {
            Demo::Sphere => include_bytes!("../fixtures/sphere/sphere.msh"),
            Demo::Naca0012 => include_bytes!("../fixtures/naca0012/naca0012.msh"),
        }
    }

    /// The bundled geometry (JSON).
    pub fn geometry_json(self) -> &'static str {
        match self {
            Demo::Sphere => include_str!("../fixtures/sphere/sphere.json"),
            Demo::Naca0012 => include_str!("../fixtures/naca0012/naca0012.json"),
        }
    }

    /// The parsed linear mesh.
    pub fn mesh(self) -> Result<LinearMesh, DemoError> {
        let name = format!("<bundled {}.msh>", self.name());
        Ok(hocurve_io::parse_msh(self.mesh_bytes(), Path::new(&name))?)
    }

    /// The parsed geometry and its association rule (by physical-group name).
    pub fn geometry(self) -> Result<(GeometryModel, AssociationRule), DemoError> {
        Ok((
            parse_geometry_json(self.geometry_json())?,
            AssociationRule::NameOnly,
        ))
    }
}

impl std::str::FromStr for Demo {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Demo::ALL
            .into_iter()
            .find(|d| d.name().eq_ignore_ascii_case(s))
            .ok_or_else(|| format!("unknown demo {s:?} (expected sphere or naca0012)"))
    }
}
