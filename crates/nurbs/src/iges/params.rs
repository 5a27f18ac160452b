//! The free-format parameters of the IGES Global and Parameter Data sections: the typed value
//! of one parameter, IGES integers and reals, and the tokenizer that splits a character
//! stream at the parameter and record delimiters (Hollerith strings `nH...` included).

use super::error::IgesError;
use super::sections::Record;

/// The value of one free-format parameter, as written.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamValue {
    /// Defaulted (nothing between two delimiters).
    Empty,
    /// A Hollerith string `nH...` (the `n` characters after the `H`).
    Str(String),
    /// Anything else: a number (integer or real) or a malformed token, trimmed.
    Token(String),
}

/// One parameter with the (1-based) file line where it starts.
#[derive(Debug, Clone, PartialEq)]
pub struct Param {
    pub value: ParamValue,
    pub line: usize,
}

impl Param {
    /// The parameter as written (for error messages).
    pub fn describe(&self) -> String {
        match &self.value {
            ParamValue::Empty => "an empty (defaulted) parameter".into(),
            ParamValue::Str(s) => format!("the string {s:?}"),
            ParamValue::Token(t) => format!("{t:?}"),
        }
    }

    /// An integer (defaulted → 0).
    pub fn as_int(&self) -> Option<i64> {
        match &self.value {
            ParamValue::Empty => Some(0),
            ParamValue::Token(t) => parse_int(t),
            ParamValue::Str(_) => None,
        }
    }

    /// A real (defaulted → 0.0); integers are accepted, `D` exponents too.
    pub fn as_real(&self) -> Option<f64> {
        match &self.value {
            ParamValue::Empty => Some(0.0),
            ParamValue::Token(t) => parse_real(t),
            ParamValue::Str(_) => None,
        }
    }

    /// A string (defaulted → empty).
    pub fn as_str(&self) -> Option<&str> {
        match &self.value {
            ParamValue::Empty => Some(""),
            ParamValue::Str(s) => Some(s),
            ParamValue::Token(_) => None,
        }
    }
}

/// An IGES integer: optional sign and decimal digits.
pub fn parse_int(t: &str) -> Option<i64> {
    let digits = t.strip_prefix(['+', '-']).unwrap_or(t);
    if digits.is_empty() || !digits.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    t.parse().ok()
}

/// An IGES real: `1.`, `.5`, `-1.5E-3`, `1.0D0`, `2` (no `inf`/`nan`).
pub fn parse_real(t: &str) -> Option<f64> {
    if t.is_empty()
        || !t.bytes().all(|b| {
            b.is_ascii_digit() || matches!(b, b'+' | b'-' | b'.' | b'e' | b'E' | b'd' | b'D')
        })
        || !t.bytes().any(|b| b.is_ascii_digit())
    {
        return None;
    }
    let s: String = t
        .chars()
        .map(|c| if c == 'd' || c == 'D' { 'E' } else { c })
        .collect();
    let mant_end = s.find('E').unwrap_or(s.len());
    if !s[..mant_end].bytes().any(|b| b.is_ascii_digit()) {
        return None;
    }
    s.parse::<f64>().ok().filter(|v| v.is_finite())
}

/// A character stream with the file line of every character.
pub(crate) struct Stream {
    pub bytes: Vec<u8>,
    pub lines: Vec<usize>,
}

impl Stream {
    /// Concatenates columns `from..=to` of the records.
    pub fn from_records(records: &[Record<'_>], from: usize, to: usize) -> Stream {
        let mut bytes = Vec::new();
        let mut lines = Vec::new();
        for r in records {
            bytes.extend_from_slice(r.cols(from, to).as_bytes());
            lines.extend((from..=to).map(|_| r.line));
        }
        Stream { bytes, lines }
    }

    /// The file line of the character at `pos` (the last line past the end).
    pub fn line_at(&self, pos: usize) -> usize {
        self.lines
            .get(pos)
            .or(self.lines.last())
            .copied()
            .unwrap_or(1)
    }
}

/// Splits the stream from `pos` into parameters separated by `pdelim` up to the record
/// delimiter `rdelim` (which must occur).
pub(crate) fn tokenize(
    s: &Stream,
    mut pos: usize,
    pdelim: u8,
    rdelim: u8,
    what: &str,
) -> Result<Vec<Param>, IgesError> {
    let b = &s.bytes;
    let mut out = Vec::new();
    loop {
        while pos < b.len() && b[pos] == b' ' && pdelim != b' ' {
            pos += 1;
        }
        if pos >= b.len() {
            return Err(IgesError::Syntax {
                line: s.line_at(pos),
                expected: format!("{what}: a parameter ended by {:?}", rdelim as char),
                found: "end of the data".into(),
            });
        }
        let line = s.line_at(pos);
        // Hollerith string?
        let mut d = pos;
        while d < b.len() && b[d].is_ascii_digit() {
            d += 1;
        }
        let value = if d > pos && d < b.len() && (b[d] == b'H' || b[d] == b'h') {
            let n: usize = std::str::from_utf8(&b[pos..d])
                .ok()
                .and_then(|t| t.parse().ok())
                .unwrap_or(usize::MAX);
            let start = d + 1;
            if n > b.len() - start {
                return Err(IgesError::Syntax {
                    line,
                    expected: format!("{what}: a Hollerith string of {n} characters"),
                    found: format!("{} characters before the end of the data", b.len() - start),
                });
            }
            let text = String::from_utf8_lossy(&b[start..start + n]).into_owned();
            pos = start + n;
            while pos < b.len() && b[pos] == b' ' && pdelim != b' ' {
                pos += 1;
            }
            ParamValue::Str(text)
        } else {
            let start = pos;
            while pos < b.len() && b[pos] != pdelim && b[pos] != rdelim {
                pos += 1;
            }
            let raw = std::str::from_utf8(&b[start..pos]).unwrap_or("");
            // blanks inside numbers are not significant in the fixed format
            let tok: String = raw.chars().filter(|c| *c != ' ').collect();
            if tok.is_empty() {
                ParamValue::Empty
            } else {
                ParamValue::Token(tok)
            }
        };
        out.push(Param { value, line });
        if pos >= b.len() {
            return Err(IgesError::Syntax {
                line: s.line_at(pos),
                expected: format!("{what}: the record delimiter {:?}", rdelim as char),
                found: "end of the data".into(),
            });
        }
        let c = b[pos];
        pos += 1;
        if c == rdelim {
            return Ok(out);
        }
        if c != pdelim {
            return Err(IgesError::Syntax {
                line: s.line_at(pos - 1),
                expected: format!(
                    "{what}: the delimiter {:?} or {:?} after a string",
                    pdelim as char, rdelim as char
                ),
                found: format!("{:?}", c as char),
            });
        }
    }
}
