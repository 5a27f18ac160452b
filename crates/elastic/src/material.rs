//! Isotropic linear elastic material: σ = λ tr(ε) I + 2μ ε (plane strain in 2D).

use crate::ElasticError;

/// Young's modulus E and Poisson's ratio ν of the fictitious solid that the mesh is.
///
/// The paper uses E = 10, ν = 0.4 (its Sect. 5); ν close to 0.5 makes the solid nearly
/// incompressible, which keeps element volumes but makes the system harder to solve.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Material {
    /// Young's modulus E > 0.
    pub young: f64,
    /// Poisson's ratio, −1 < ν < 0.5.
    pub poisson: f64,
}

impl Default for Material {
    fn default() -> Self {
        Material {
            young: 10.0,
            poisson: 0.4,
        }
    }
}

impl Material {
    /// A checked material.
    pub fn new(young: f64, poisson: f64) -> Result<Self, ElasticError> {
        let material = Material { young, poisson };
        material.validate()?;
        Ok(material)
    }

    /// Error unless E > 0 (finite) and −1 < ν < 0.5.
    pub fn validate(&self) -> Result<(), ElasticError> {
        let ok =
            self.young.is_finite() && self.young > 0.0 && self.poisson > -1.0 && self.poisson < 0.5;
        if ok {
            Ok(())
        } else {
            Err(ElasticError::InvalidMaterial {
                young: self.young,
                poisson: self.poisson,
            })
        }
    }

    /// Lamé parameters (λ, μ): λ = Eν / ((1 + ν)(1 − 2ν)), μ = E / (2(1 + ν)). In 2D these
    /// are used as they are, which is plane strain (ε_zz = 0).
    pub fn lame(&self) -> (f64, f64) {
        let (e, nu) = (self.young, self.poisson);
        (
            e * nu / ((1.0 + nu) * (1.0 - 2.0 * nu)),
            e / (2.0 * (1.0 + nu)),
        )
    }
}

#[cfg(test)]
#[path = "tests/material.rs"]
mod tests;
