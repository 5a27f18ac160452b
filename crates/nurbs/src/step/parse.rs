//! ISO 10303-21 ("Part 21", the STEP exchange structure) as data: every instance of the DATA
//! section with its parameters, nothing interpreted.
//!
//! An instance is `#id = NAME(params);` or, for a complex entity (rational B-splines, units),
//! `#id = (NAME1(params) NAME2(params) …);`. Parameters are integers, reals (`1.`, `1.E-07`),
//! strings (`'it''s'`), enumerations (`.T.`), references (`#12`), lists, unset `$`, derived
//! `*` and typed values (`LENGTH_MEASURE(1.E-07)`). Comments `/* … */` may appear anywhere
//! between tokens. The HEADER section is read with the same grammar and dropped.

use std::collections::BTreeMap;
use std::path::Path;

use super::error::StepError;

/// One parameter value.
#[derive(Debug, Clone, PartialEq)]
pub enum StepValue {
    Integer(i64),
    Real(f64),
    String(String),
    Enumeration(String),
    Reference(u64),
    List(Vec<StepValue>),
    /// `$`: no value.
    Unset,
    /// `*`: derived from a supertype.
    Derived,
    /// `NAME(value)`: a value with its type, e.g. `LENGTH_MEASURE(1.E-07)`.
    Typed(String, Vec<StepValue>),
}

impl StepValue {
    /// The value as a real (integers too).
    pub fn real(&self) -> Option<f64> {
        match *self {
            StepValue::Real(x) => Some(x),
            StepValue::Integer(i) => Some(i as f64),
            StepValue::Typed(_, ref v) if v.len() == 1 => v[0].real(),
            _ => None,
        }
    }

    /// The referenced instance.
    pub fn reference(&self) -> Option<u64> {
        match *self {
            StepValue::Reference(r) => Some(r),
            _ => None,
        }
    }

    /// The items of a list.
    pub fn list(&self) -> Option<&[StepValue]> {
        match self {
            StepValue::List(v) => Some(v),
            _ => None,
        }
    }

    /// An enumeration's name (without the dots), e.g. `T` for `.T.`.
    pub fn enumeration(&self) -> Option<&str> {
        match self {
            StepValue::Enumeration(e) => Some(e),
            _ => None,
        }
    }
}

/// `NAME(params)`: a simple instance, or one part of a complex one.
#[derive(Debug, Clone, PartialEq)]
pub struct StepRecord {
    /// The entity type, upper case.
    pub name: String,
    pub params: Vec<StepValue>,
}

/// One instance of the DATA section.
#[derive(Debug, Clone, PartialEq)]
pub struct StepInstance {
    pub id: u64,
    /// 1-based line where `#id` is written.
    pub line: usize,
    /// One record, or several for a complex instance (in file order).
    pub records: Vec<StepRecord>,
}

impl StepInstance {
    /// The instance's type for messages: its name, or the names of a complex instance's
    /// parts joined by `+`.
    pub fn type_name(&self) -> String {
        let names: Vec<&str> = self.records.iter().map(|r| r.name.as_str()).collect();
        names.join("+")
    }

    /// The record named `name` (a simple instance of that type, or that part of a complex
    /// one).
    pub fn record(&self, name: &str) -> Option<&StepRecord> {
        self.records.iter().find(|r| r.name == name)
    }
}

/// The instances of a STEP file by id.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StepFile {
    pub instances: BTreeMap<u64, StepInstance>,
}

/// Reads and parses a STEP file.
pub fn read_step(path: &Path) -> Result<StepFile, StepError> {
    let bytes = std::fs::read(path).map_err(|source| StepError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_step(&bytes)
}

/// Parses the text of a STEP file (ISO 10303-21).
pub fn parse_step(bytes: &[u8]) -> Result<StepFile, StepError> {
    let mut p = Parser {
        bytes,
        pos: 0,
        line: 1,
        depth: 0,
    };
    p.skip_space()?;
    p.keyword("ISO-10303-21")?;
    p.expect(b';')?;
    let mut file = StepFile::default();
    loop {
        p.skip_space()?;
        if p.at_end() {
            return Err(p.error("the file ends before END-ISO-10303-21;"));
        }
        let word = p.word()?;
        match word.as_str() {
            "HEADER" | "DATA" => {
                p.skip_space()?;
                // DATA may carry a parameter list naming the section (edition 3).
                if p.peek() == Some(b'(') {
                    p.value()?;
                    p.skip_space()?;
                }
                p.expect(b';')?;
                p.section(word == "DATA", &mut file)?;
            }
            "END-ISO-10303-21" => {
                p.skip_space()?;
                p.expect(b';')?;
                return Ok(file);
            }
            other => {
                return Err(p.error(&format!(
                    "expected HEADER, DATA or END-ISO-10303-21, found {other:?}"
                )))
            }
        }
    }
}

struct Parser<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
    /// Lists open around the current value (bounded: no stack overflow on hostile input).
    depth: usize,
}

/// Deepest nesting of parameter lists read (STEP geometry nests two or three deep).
const MAX_NESTING: usize = 64;

impl Parser<'_> {
    fn error(&self, message: &str) -> StepError {
        StepError::Syntax {
            line: self.line,
            message: message.to_string(),
        }
    }

    fn at_end(&self) -> bool {
        self.pos >= self.bytes.len()
    }

    fn peek(&self) -> Option<u8> {
        self.bytes.get(self.pos).copied()
    }

    fn bump(&mut self) -> Option<u8> {
        let b = self.peek()?;
        self.pos += 1;
        if b == b'\n' {
            self.line += 1;
        }
        Some(b)
    }

    /// Skips white space and comments.
    fn skip_space(&mut self) -> Result<(), StepError> {
        loop {
            match self.peek() {
                Some(b) if b.is_ascii_whitespace() => {
                    self.bump();
                }
                Some(b'/') if self.bytes.get(self.pos + 1) == Some(&b'*') => {
                    let start = self.line;
                    self.pos += 2;
                    loop {
                        match self.bump() {
                            None => {
                                return Err(StepError::Syntax {
                                    line: start,
                                    message: "unterminated comment".into(),
                                })
                            }
                            Some(b'*') if self.peek() == Some(b'/') => {
                                self.pos += 1;
                                break;
                            }
                            Some(_) => {}
                        }
                    }
                }
                _ => return Ok(()),
            }
        }
    }

    fn expect(&mut self, b: u8) -> Result<(), StepError> {
        if self.peek() == Some(b) {
            self.bump();
            Ok(())
        } else {
            Err(self.error(&format!(
                "expected '{}', found {}",
                b as char,
                self.describe_next()
            )))
        }
    }

    fn describe_next(&self) -> String {
        match self.peek() {
            None => "the end of the file".into(),
            Some(b) => format!("'{}'", b as char),
        }
    }

    /// A keyword or entity name: letters, digits, `_` and `-`, upper-cased.
    fn word(&mut self) -> Result<String, StepError> {
        let start = self.pos;
        while matches!(self.peek(), Some(b) if b.is_ascii_alphanumeric() || b == b'_' || b == b'-')
        {
            self.pos += 1;
        }
        if start == self.pos {
            return Err(self.error(&format!("expected a name, found {}", self.describe_next())));
        }
        Ok(String::from_utf8_lossy(&self.bytes[start..self.pos]).to_ascii_uppercase())
    }

    fn keyword(&mut self, expected: &str) -> Result<(), StepError> {
        let w = self.word()?;
        if w == expected {
            Ok(())
        } else {
            Err(self.error(&format!("expected {expected}, found {w}")))
        }
    }

    /// The instances up to ENDSEC; kept when `keep` (DATA), dropped otherwise (HEADER).
    fn section(&mut self, keep: bool, file: &mut StepFile) -> Result<(), StepError> {
        loop {
            self.skip_space()?;
            match self.peek() {
                None => return Err(self.error("the file ends inside a section (no ENDSEC;)")),
                Some(b'#') => {
                    let line = self.line;
                    self.bump();
                    let id = self.unsigned()?;
                    self.skip_space()?;
                    self.expect(b'=')?;
                    self.skip_space()?;
                    let records = self.records()?;
                    self.skip_space()?;
                    self.expect(b';')?;
                    if keep {
                        let instance = StepInstance { id, line, records };
                        if file.instances.insert(id, instance).is_some() {
                            return Err(StepError::Duplicate { line, id });
                        }
                    }
                }
                Some(_) => {
                    let word = self.word()?;
                    if word == "ENDSEC" {
                        self.skip_space()?;
                        return self.expect(b';');
                    }
                    // A header entity: NAME(params);
                    self.skip_space()?;
                    self.params()?;
                    self.skip_space()?;
                    self.expect(b';')?;
                }
            }
        }
    }

    /// `NAME(params)` or `(NAME(params) NAME(params) …)`.
    fn records(&mut self) -> Result<Vec<StepRecord>, StepError> {
        if self.peek() == Some(b'(') {
            self.bump();
            let mut records = Vec::new();
            loop {
                self.skip_space()?;
                if self.peek() == Some(b')') {
                    self.bump();
                    break;
                }
                records.push(self.record()?);
            }
            if records.is_empty() {
                return Err(self.error("a complex instance with no part"));
            }
            Ok(records)
        } else {
            Ok(vec![self.record()?])
        }
    }

    fn record(&mut self) -> Result<StepRecord, StepError> {
        let name = self.word()?;
        self.skip_space()?;
        let params = self.params()?;
        Ok(StepRecord { name, params })
    }

    /// `(v, v, …)`.
    fn params(&mut self) -> Result<Vec<StepValue>, StepError> {
        if self.depth >= MAX_NESTING {
            return Err(self.error(&format!(
                "parameter lists nested more than {MAX_NESTING} deep"
            )));
        }
        self.depth += 1;
        let values = self.list();
        self.depth -= 1;
        values
    }

    fn list(&mut self) -> Result<Vec<StepValue>, StepError> {
        self.expect(b'(')?;
        let mut values = Vec::new();
        self.skip_space()?;
        if self.peek() == Some(b')') {
            self.bump();
            return Ok(values);
        }
        loop {
            self.skip_space()?;
            values.push(self.value()?);
            self.skip_space()?;
            match self.bump() {
                Some(b',') => continue,
                Some(b')') => return Ok(values),
                other => {
                    return Err(self.error(&format!(
                        "expected ',' or ')' in a parameter list, found {}",
                        other.map_or("the end of the file".into(), |b| format!("'{}'", b as char))
                    )))
                }
            }
        }
    }

    fn unsigned(&mut self) -> Result<u64, StepError> {
        let start = self.pos;
        while matches!(self.peek(), Some(b) if b.is_ascii_digit()) {
            self.pos += 1;
        }
        std::str::from_utf8(&self.bytes[start..self.pos])
            .ok()
            .and_then(|s| s.parse().ok())
            .ok_or_else(|| self.error("expected an instance number after '#'"))
    }

    fn value(&mut self) -> Result<StepValue, StepError> {
        match self.peek() {
            Some(b'#') => {
                self.bump();
                Ok(StepValue::Reference(self.unsigned()?))
            }
            Some(b'$') => {
                self.bump();
                Ok(StepValue::Unset)
            }
            Some(b'*') => {
                self.bump();
                Ok(StepValue::Derived)
            }
            Some(b'(') => Ok(StepValue::List(self.params()?)),
            Some(b'\'') => self.string(),
            Some(b'"') => {
                // Binary: hex digits in double quotes; kept as text.
                self.bump();
                let start = self.pos;
                while !matches!(self.peek(), Some(b'"') | None) {
                    self.bump();
                }
                let text = String::from_utf8_lossy(&self.bytes[start..self.pos]).into_owned();
                self.expect(b'"')?;
                Ok(StepValue::String(text))
            }
            Some(b'.') => {
                self.bump();
                let name = self.word()?;
                self.expect(b'.')?;
                Ok(StepValue::Enumeration(name))
            }
            Some(b) if b == b'+' || b == b'-' || b.is_ascii_digit() => self.number(),
            Some(b) if b.is_ascii_alphabetic() => {
                let name = self.word()?;
                self.skip_space()?;
                Ok(StepValue::Typed(name, self.params()?))
            }
            _ => Err(self.error(&format!(
                "expected a parameter value, found {}",
                self.describe_next()
            ))),
        }
    }

    fn string(&mut self) -> Result<StepValue, StepError> {
        let line = self.line;
        self.bump();
        let mut text = Vec::new();
        loop {
            match self.bump() {
                None => {
                    return Err(StepError::Syntax {
                        line,
                        message: "unterminated string".into(),
                    })
                }
                Some(b'\'') if self.peek() == Some(b'\'') => {
                    self.bump();
                    text.push(b'\'');
                }
                Some(b'\'') => break,
                Some(b) => text.push(b),
            }
        }
        Ok(StepValue::String(
            String::from_utf8_lossy(&text).into_owned(),
        ))
    }

    fn number(&mut self) -> Result<StepValue, StepError> {
        let start = self.pos;
        if matches!(self.peek(), Some(b'+' | b'-')) {
            self.pos += 1;
        }
        let mut real = false;
        while let Some(b) = self.peek() {
            match b {
                b'0'..=b'9' => {}
                b'.' | b'E' | b'e' => real = true,
                b'+' | b'-' if matches!(self.bytes[self.pos - 1], b'E' | b'e') => {}
                _ => break,
            }
            self.pos += 1;
        }
        let text = std::str::from_utf8(&self.bytes[start..self.pos]).unwrap_or("");
        let bad = || self.error(&format!("{text:?} is not a number"));
        if real {
            // STEP allows "1." and "1.E-07": Rust's parser takes both.
            text.parse().map(StepValue::Real).map_err(|_| bad())
        } else {
            text.parse().map(StepValue::Integer).map_err(|_| bad())
        }
    }
}

#[cfg(test)]
#[path = "tests/parse.rs"]
mod tests;
