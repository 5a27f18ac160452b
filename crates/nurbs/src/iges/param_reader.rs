//! Sequential, typed reading of one entity's Parameter Data fields: each value is checked
//! as it is taken and every error names the field, its line and what was found; the DE
//! pointers read are collected for validation.

use super::error::IgesError;
use super::params::Param;
use crate::basis::MAX_DEGREE;

/// What a degree must be (the text of [`IgesError::Parameter`] is static).
const DEGREE_EXPECTED: &str = "a degree from 0 to 24 (the highest supported)";
// keeps the message above true
const _: () = assert!(MAX_DEGREE == 24);

/// A DE pointer read from a parameter, with its file line (for validation).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Reference {
    pub pointer: u32,
    pub line: usize,
    pub index: usize,
    pub name: &'static str,
}

/// Sequential reader of one entity's parameters.
pub(crate) struct Reader<'a> {
    params: &'a [Param],
    next: usize,
    de: u32,
    entity_type: i32,
    end_line: usize,
    pub refs: Vec<Reference>,
}

impl<'a> Reader<'a> {
    pub fn new(params: &'a [Param], de: u32, entity_type: i32, end_line: usize) -> Self {
        Reader {
            params,
            next: 0,
            de,
            entity_type,
            end_line,
            refs: Vec::new(),
        }
    }

    fn error(&self, index: usize, name: &'static str, expected: &'static str) -> IgesError {
        let (line, found) = match self.params.get(index) {
            Some(p) => (p.line, p.describe()),
            None => (self.end_line, "the end of the parameter record".to_string()),
        };
        IgesError::Parameter {
            line,
            de: self.de,
            entity_type: self.entity_type,
            index,
            name,
            expected,
            found,
        }
    }

    fn take(&mut self, name: &'static str, expected: &'static str) -> Result<&'a Param, IgesError> {
        let i = self.next;
        match self.params.get(i) {
            Some(p) => {
                self.next += 1;
                Ok(p)
            }
            None => Err(self.error(i, name, expected)),
        }
    }

    /// The number of parameters not read yet.
    pub fn remaining(&self) -> usize {
        self.params.len().saturating_sub(self.next)
    }

    /// The parameters not read yet (kept raw, for entities not interpreted).
    pub fn rest(&self) -> Vec<Param> {
        self.params[self.next.min(self.params.len())..].to_vec()
    }

    /// A real number (integers and `D` exponents accepted, defaulted → 0).
    pub fn real(&mut self, name: &'static str) -> Result<f64, IgesError> {
        let i = self.next;
        let p = self.take(name, "a real number")?;
        p.as_real()
            .ok_or_else(|| self.error(i, name, "a real number"))
    }

    /// An integer (defaulted → 0).
    pub fn int(&mut self, name: &'static str) -> Result<i64, IgesError> {
        let i = self.next;
        let p = self.take(name, "an integer")?;
        p.as_int().ok_or_else(|| self.error(i, name, "an integer"))
    }

    /// A 0/1 flag.
    pub fn flag(&mut self, name: &'static str) -> Result<bool, IgesError> {
        let i = self.next;
        match self.int(name)? {
            0 => Ok(false),
            1 => Ok(true),
            _ => Err(self.error(i, name, "0 or 1")),
        }
    }

    /// A non-negative count of which `per_item` parameters each must still follow.
    pub fn count(&mut self, name: &'static str, per_item: usize) -> Result<usize, IgesError> {
        let i = self.next;
        let v = self.int(name)?;
        if v < 0 {
            return Err(self.error(i, name, "a non-negative integer"));
        }
        let n = v as usize;
        match n.checked_mul(per_item) {
            Some(t) if t <= self.remaining() => {}
            _ => {
                return Err(self.error(
                    i,
                    name,
                    "a count not larger than the parameters that follow",
                ));
            }
        }
        Ok(n)
    }

    /// An optional DE pointer (0 or defaulted → `None`).
    pub fn opt_ptr(&mut self, name: &'static str) -> Result<Option<u32>, IgesError> {
        let i = self.next;
        let v = self.int(name)?;
        if v == 0 {
            return Ok(None);
        }
        if v < 0 || v > u32::MAX as i64 {
            return Err(self.error(i, name, "a DE pointer (positive odd integer)"));
        }
        self.refs.push(Reference {
            pointer: v as u32,
            line: self.params[i].line,
            index: i,
            name,
        });
        Ok(Some(v as u32))
    }

    /// A required DE pointer.
    pub fn ptr(&mut self, name: &'static str) -> Result<u32, IgesError> {
        let i = self.next;
        self.opt_ptr(name)?
            .ok_or_else(|| self.error(i, name, "a DE pointer (positive odd integer)"))
    }

    /// A 2D point (two reals).
    pub fn xy(&mut self, nx: &'static str, ny: &'static str) -> Result<[f64; 2], IgesError> {
        Ok([self.real(nx)?, self.real(ny)?])
    }

    /// A 3D point (three reals).
    pub fn xyz(
        &mut self,
        nx: &'static str,
        ny: &'static str,
        nz: &'static str,
    ) -> Result<[f64; 3], IgesError> {
        Ok([self.real(nx)?, self.real(ny)?, self.real(nz)?])
    }

    /// `n` reals of one array field.
    pub fn reals(&mut self, n: usize, name: &'static str) -> Result<Vec<f64>, IgesError> {
        (0..n).map(|_| self.real(name)).collect()
    }

    /// `n` control points (X, Y, Z each).
    pub fn points(&mut self, n: usize) -> Result<Vec<[f64; 3]>, IgesError> {
        (0..n).map(|_| self.xyz("X", "Y", "Z")).collect()
    }

    /// A B-spline degree: at most [`MAX_DEGREE`], which bounds the work of every later
    /// step (degree elevation, knot insertion) whatever the file says.
    pub fn degree(&mut self, name: &'static str) -> Result<usize, IgesError> {
        let i = self.next;
        let m = self.non_negative(name)?;
        if m > MAX_DEGREE {
            return Err(self.error(i, name, DEGREE_EXPECTED));
        }
        Ok(m)
    }

    /// An array size: non-negative and not above the parameter count, so that sizes
    /// computed from it cannot overflow.
    pub fn non_negative(&mut self, name: &'static str) -> Result<usize, IgesError> {
        let i = self.next;
        let v = self.int(name)?;
        if v < 0 || v > self.params.len() as i64 {
            return Err(self.error(
                i,
                name,
                "a non-negative integer not larger than the parameter count",
            ));
        }
        Ok(v as usize)
    }

    /// Checks that `n` more parameters follow (for sizes computed from several fields).
    pub fn need(
        &self,
        n: Option<usize>,
        name: &'static str,
        at: usize,
    ) -> Result<usize, IgesError> {
        match n {
            Some(n) if n <= self.remaining() => Ok(n),
            _ => Err(self.error(
                at,
                name,
                "array sizes that fit in the parameters that follow",
            )),
        }
    }
}
