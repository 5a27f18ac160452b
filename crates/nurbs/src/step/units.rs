//! The file's units: lengths to millimetres and plane angles to radians, as OpenCASCADE
//! reads STEP (so the geometry is in the numbers of a mesh Gmsh makes from the file).

use super::convert::{Converter, MAX_DEPTH, SAME};
use super::error::StepError;
use super::parse::{StepInstance, StepValue};

/// SI prefixes as powers of ten.
const SI_PREFIXES: [(&str, i32); 16] = [
    ("EXA", 18),
    ("PETA", 15),
    ("TERA", 12),
    ("GIGA", 9),
    ("MEGA", 6),
    ("KILO", 3),
    ("HECTO", 2),
    ("DECA", 1),
    ("DECI", -1),
    ("CENTI", -2),
    ("MILLI", -3),
    ("MICRO", -6),
    ("NANO", -9),
    ("PICO", -12),
    ("FEMTO", -15),
    ("ATTO", -18),
];

impl Converter<'_> {
    /// The size of the geometry's unit of `kind` (`LENGTH_UNIT`: in metres;
    /// `PLANE_ANGLE_UNIT`: in radians) as the contexts of the representations holding faces
    /// or edges assign it (`GLOBAL_UNIT_ASSIGNED_CONTEXT`; every context when no
    /// representation holds any), None when they assign none. Other contexts may differ (an
    /// Inventor part's placement in inches around its B-rep in millimetres); geometry in
    /// different units is refused.
    pub(super) fn unit_factor(&self, kind: &str) -> Result<Option<f64>, StepError> {
        let mut contexts = self.geometry_contexts()?;
        if contexts.is_empty() {
            contexts = self
                .file
                .instances
                .values()
                .filter(|c| c.record("GLOBAL_UNIT_ASSIGNED_CONTEXT").is_some())
                .collect();
        }
        let mut found: Option<(f64, &StepInstance)> = None;
        for c in contexts {
            let Some((f, i)) = self.context_unit(c, kind)? else {
                continue;
            };
            match found {
                Some((g, first)) if (f - g).abs() > SAME * g.abs() => {
                    return Err(self.unsupported(
                        i,
                        format!(
                            " (a second {kind}, {f} against {g} of #{}: mixed units)",
                            first.id
                        ),
                    ))
                }
                None => found = Some((f, i)),
                _ => {}
            }
        }
        Ok(found.map(|(f, _)| f))
    }

    /// The largest length uncertainty (`UNCERTAINTY_MEASURE_WITH_UNIT` of a length, in a
    /// `GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT`) of the contexts holding faces or edges (every
    /// context when none holds any), in millimetres; None when they state none.
    pub(super) fn length_uncertainty(&self) -> Result<Option<f64>, StepError> {
        let mut contexts = self.geometry_contexts()?;
        if contexts.is_empty() {
            contexts = self.file.instances.values().collect();
        }
        let mut largest: Option<f64> = None;
        for c in contexts {
            let Some(r) = c.record("GLOBAL_UNCERTAINTY_ASSIGNED_CONTEXT") else {
                continue;
            };
            for u in r.params.first().and_then(StepValue::list).unwrap_or(&[]) {
                let i = self.get(u, c)?;
                let Some(m) = i.record("UNCERTAINTY_MEASURE_WITH_UNIT") else {
                    continue;
                };
                let (Some(value), Some(unit)) =
                    (m.params.first().and_then(StepValue::real), m.params.get(1))
                else {
                    continue;
                };
                let unit = self.get(unit, i)?;
                if unit.record("LENGTH_UNIT").is_none() || !value.is_finite() || value <= 0.0 {
                    continue;
                }
                let mm = 1000.0 * value * self.unit_size(unit, 0)?;
                if mm.is_finite() {
                    largest = Some(largest.map_or(mm, |l: f64| l.max(mm)));
                }
            }
        }
        Ok(largest)
    }

    /// The unit of `kind` a representation context assigns, in SI base units, with the
    /// unit instance; None when it assigns none (or is not a context with units).
    pub(super) fn context_unit<'i>(
        &'i self,
        context: &'i StepInstance,
        kind: &str,
    ) -> Result<Option<(f64, &'i StepInstance)>, StepError> {
        let Some(r) = context.record("GLOBAL_UNIT_ASSIGNED_CONTEXT") else {
            return Ok(None);
        };
        for u in r.params.first().and_then(StepValue::list).unwrap_or(&[]) {
            let i = self.get(u, context)?;
            if i.record(kind).is_some() {
                return Ok(Some((self.unit_size(i, 0)?, i)));
            }
        }
        Ok(None)
    }

    /// Millimetres per length unit of representation `rep`'s context (the file's geometry
    /// unit when its context assigns none).
    pub(super) fn representation_length(&self, rep: &StepInstance) -> Result<f64, StepError> {
        let Some(context) = self.representation_context(rep) else {
            return Ok(self.length);
        };
        Ok(self
            .context_unit(context, "LENGTH_UNIT")?
            .map_or(self.length, |(metres, _)| 1000.0 * metres))
    }

    /// The size of a unit instance in SI base units (metre, radian).
    pub(super) fn unit_size(&self, i: &StepInstance, depth: usize) -> Result<f64, StepError> {
        if depth > MAX_DEPTH {
            return Err(StepError::TooDeep {
                id: i.id,
                line: i.line,
                limit: MAX_DEPTH,
            });
        }
        if let Some(si) = i.record("SI_UNIT") {
            let prefix = match si.params.first() {
                Some(StepValue::Enumeration(p)) => SI_PREFIXES
                    .iter()
                    .find(|(name, _)| name == p)
                    .map(|&(_, e)| e)
                    .ok_or_else(|| self.unsupported(i, format!(" (SI prefix {p})")))?,
                _ => 0,
            };
            return match si.params.get(1).and_then(StepValue::enumeration) {
                Some("METRE" | "RADIAN") => Ok(10f64.powi(prefix)),
                other => Err(self.unsupported(i, format!(" (SI unit {other:?})"))),
            };
        }
        if let Some(c) = i.record("CONVERSION_BASED_UNIT") {
            let measure = c
                .params
                .get(1)
                .ok_or_else(|| self.fail(i, "a conversion-based unit without its measure"))?;
            let m = self.get(measure, i)?;
            let p = &m.records[0].params;
            let (Some(value), Some(unit)) = (p.first().and_then(StepValue::real), p.get(1)) else {
                return Err(self.fail(m, "expected a value and a unit"));
            };
            let base = self.unit_size(self.get(unit, m)?, depth + 1)?;
            let size = value * base;
            if size.is_nan() || size <= 0.0 {
                return Err(self.fail(i, format!("a unit of size {size}")));
            }
            return Ok(size);
        }
        Err(self.unsupported(i, " (as a unit)"))
    }

    /// A length parameter, in millimetres.
    pub(super) fn length(
        &self,
        v: &StepValue,
        i: &StepInstance,
        what: &str,
    ) -> Result<f64, StepError> {
        Ok(self.real(v, i, what)? * self.length)
    }
}
