//! The IGES 5.3 fixed (ASCII, 80-column) file format: records and sections, the free-format
//! parameter tokenizer (delimiters, Hollerith strings), the Global section and the Directory
//! Entry pairs.

use super::IgesError;

/// One 80-column record of the file.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Record<'a> {
    /// 1-based line number in the file.
    pub line: usize,
    /// The whole record (exactly 80 ASCII characters).
    pub text: &'a str,
}

impl<'a> Record<'a> {
    /// Columns `from..=to` (1-based, inclusive).
    pub fn cols(&self, from: usize, to: usize) -> &'a str {
        &self.text[from - 1..to]
    }
}

/// The records of a file split into its five sections.
#[derive(Debug, Default)]
pub(crate) struct Sections<'a> {
    pub start: Vec<Record<'a>>,
    pub global: Vec<Record<'a>>,
    pub directory: Vec<Record<'a>>,
    pub parameter: Vec<Record<'a>>,
    pub terminate: Vec<Record<'a>>,
}

fn section_name(letter: u8) -> &'static str {
    match letter {
        b'S' => "Start (S)",
        b'G' => "Global (G)",
        b'D' => "Directory Entry (D)",
        b'P' => "Parameter Data (P)",
        _ => "Terminate (T)",
    }
}

/// Splits the text into 80-column records and checks section letters, section order and
/// sequence numbers (1, 2, 3, ... in each section).
pub(crate) fn split_sections(text: &str) -> Result<Sections<'_>, IgesError> {
    let mut lines: Vec<&str> = text
        .split('\n')
        .map(|l| l.strip_suffix('\r').unwrap_or(l))
        .collect();
    // trailing blank lines (and the empty piece after the final newline) are not records
    while lines.last().is_some_and(|l| l.trim().is_empty()) {
        lines.pop();
    }
    if lines.is_empty() {
        return Err(IgesError::Syntax {
            line: 1,
            expected: "an IGES Start (S) record".into(),
            found: "an empty file".into(),
        });
    }
    let order = [b'S', b'G', b'D', b'P', b'T'];
    let mut sections = Sections::default();
    let mut current = 0usize; // index into `order`
    let mut expected_seq = 1u32;
    for (i, raw) in lines.iter().enumerate() {
        let line = i + 1;
        if !raw.is_ascii() {
            return Err(IgesError::Syntax {
                line,
                expected: "ASCII characters only".into(),
                found: "a non-ASCII character".into(),
            });
        }
        if raw.len() != 80 {
            return Err(IgesError::Syntax {
                line,
                expected: "a record of 80 columns".into(),
                found: format!("{} columns", raw.len()),
            });
        }
        let rec = Record { line, text: raw };
        let letter = raw.as_bytes()[72];
        let Some(pos) = order.iter().position(|&c| c == letter) else {
            let found = letter as char;
            let expected = if i == 0 && matches!(found, 'B' | 'C' | 'F') {
                "the fixed ASCII form (binary and compressed IGES are not supported)".to_string()
            } else {
                "one of the section letters S, G, D, P, T".to_string()
            };
            return Err(IgesError::Section {
                line,
                expected,
                found,
            });
        };
        if i == 0 && pos != 0 {
            return Err(IgesError::Section {
                line,
                expected: "a Start (S) record first".into(),
                found: letter as char,
            });
        }
        if pos < current {
            return Err(IgesError::Section {
                line,
                expected: format!(
                    "a record of the {} section or a later one",
                    section_name(order[current])
                ),
                found: letter as char,
            });
        }
        if pos > current {
            if current == 0 && pos != 1 {
                return Err(IgesError::Section {
                    line,
                    expected: "a Global (G) record after the Start section".into(),
                    found: letter as char,
                });
            }
            current = pos;
            expected_seq = 1;
        }
        let seq_text = rec.cols(74, 80);
        let seq: Option<u32> = seq_text.trim().parse().ok();
        if seq != Some(expected_seq) {
            return Err(IgesError::Sequence {
                line,
                section: letter as char,
                expected: expected_seq,
                found: seq_text.to_string(),
            });
        }
        expected_seq += 1;
        match letter {
            b'S' => sections.start.push(rec),
            b'G' => sections.global.push(rec),
            b'D' => sections.directory.push(rec),
            b'P' => sections.parameter.push(rec),
            _ => sections.terminate.push(rec),
        }
    }
    let last = lines.len();
    if sections.global.is_empty() {
        return Err(IgesError::Syntax {
            line: last + 1,
            expected: "a Global (G) section".into(),
            found: "end of file".into(),
        });
    }
    if sections.terminate.is_empty() {
        return Err(IgesError::Syntax {
            line: last + 1,
            expected: "the Terminate (T) record".into(),
            found: "end of file".into(),
        });
    }
    if sections.terminate.len() > 1 {
        return Err(IgesError::Syntax {
            line: sections.terminate[1].line,
            expected: "a single Terminate (T) record".into(),
            found: "a second one".into(),
        });
    }
    // the Terminate record counts the records of the other sections
    let t = sections.terminate[0];
    let counts = [
        (sections.start.len(), 'S'),
        (sections.global.len(), 'G'),
        (sections.directory.len(), 'D'),
        (sections.parameter.len(), 'P'),
    ];
    for (k, &(n, letter)) in counts.iter().enumerate() {
        let field = t.cols(8 * k + 1, 8 * k + 8);
        let expected = format!("{letter}{n:>7}");
        let ok = field.starts_with(letter) && field[1..].trim().parse::<usize>().ok() == Some(n);
        if !ok {
            return Err(IgesError::Syntax {
                line: t.line,
                expected: format!("Terminate field {} = {:?}", k + 1, expected),
                found: format!("{field:?}"),
            });
        }
    }
    if sections.directory.len() % 2 != 0 {
        let line = sections.directory.last().map_or(t.line, |r| r.line);
        return Err(IgesError::Syntax {
            line,
            expected: "Directory Entry records in pairs (an even count)".into(),
            found: format!("{} records", sections.directory.len()),
        });
    }
    Ok(sections)
}

// ---------------------------------------------------------------------------------------------
// free-format parameters
// ---------------------------------------------------------------------------------------------

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

    fn line_at(&self, pos: usize) -> usize {
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

// ---------------------------------------------------------------------------------------------
// Global section
// ---------------------------------------------------------------------------------------------

/// The Global section (IGES 5.3 §2.2.4). Fields missing at the end of the section take their
/// defaults (empty strings, zeros).
#[derive(Debug, Clone, PartialEq)]
pub struct GlobalSection {
    /// 1: parameter delimiter (default `,`).
    pub parameter_delimiter: char,
    /// 2: record delimiter (default `;`).
    pub record_delimiter: char,
    /// 3: product identification from the sender.
    pub product_id_sender: String,
    /// 4: file name.
    pub file_name: String,
    /// 5: native system ID.
    pub native_system_id: String,
    /// 6: preprocessor version.
    pub preprocessor_version: String,
    /// 7: number of binary bits for integer representation.
    pub integer_bits: i64,
    /// 8–11: single precision magnitude/significance, double precision magnitude/significance.
    pub single_precision_magnitude: i64,
    pub single_precision_significance: i64,
    pub double_precision_magnitude: i64,
    pub double_precision_significance: i64,
    /// 12: product identification for the receiver.
    pub product_id_receiver: String,
    /// 13: model space scale (default 1).
    pub model_space_scale: f64,
    /// 14: units flag (1 inch, 2 mm, 3 see `units_name`, 4 ft, 5 mi, 6 m, 7 km, 8 mil,
    /// 9 micron, 10 cm, 11 microinch).
    pub units_flag: i64,
    /// 15: units name (`MM`, `IN`, ...).
    pub units_name: String,
    /// 16: maximum number of line weight gradations.
    pub max_line_weight_gradations: i64,
    /// 17: width of the maximum line weight in units.
    pub max_line_weight: f64,
    /// 18: date and time of the file generation.
    pub date: String,
    /// 19: minimum user-intended resolution (model units).
    pub min_resolution: f64,
    /// 20: approximate maximum coordinate value (`None` when 0 or defaulted).
    pub max_coordinate: Option<f64>,
    /// 21: author.
    pub author: String,
    /// 22: author's organization.
    pub organization: String,
    /// 23: IGES version flag (11 = 5.3).
    pub version: i64,
    /// 24: drafting standard flag.
    pub drafting_standard: i64,
    /// 25: date and time the model was created or modified.
    pub modified_date: String,
    /// 26: application protocol/subset identifier.
    pub application_protocol: String,
}

impl GlobalSection {
    /// Size of one model unit in metres (from the units flag; `None` for flag 3 or unknown).
    pub fn unit_in_metres(&self) -> Option<f64> {
        Some(match self.units_flag {
            1 => 0.0254,
            2 => 1e-3,
            4 => 0.3048,
            5 => 1609.344,
            6 => 1.0,
            7 => 1e3,
            8 => 2.54e-5,
            9 => 1e-6,
            10 => 1e-2,
            11 => 2.54e-8,
            _ => return None,
        })
    }
}

fn single_char_delimiter(b: &[u8], pos: usize, line: usize, which: &str) -> Result<u8, IgesError> {
    // expects "1Hx" at pos
    if b.len() >= pos + 3 && b[pos] == b'1' && (b[pos + 1] == b'H' || b[pos + 1] == b'h') {
        let c = b[pos + 2];
        if c == b' ' || c.is_ascii_digit() || c == b'+' || c == b'-' || c == b'.' {
            return Err(IgesError::Syntax {
                line,
                expected: format!("Global section: a usable {which}"),
                found: format!("{:?}", c as char),
            });
        }
        Ok(c)
    } else {
        let found = String::from_utf8_lossy(&b[pos..b.len().min(pos + 8)]).into_owned();
        Err(IgesError::Syntax {
            line,
            expected: format!("Global section: the {which} as `1Hx` or defaulted"),
            found: format!("{found:?}"),
        })
    }
}

/// Parses the Global section (columns 1–72 of the G records).
pub(crate) fn parse_global(records: &[Record<'_>]) -> Result<GlobalSection, IgesError> {
    let s = Stream::from_records(records, 1, 72);
    let b = &s.bytes;
    let line0 = records[0].line;
    // field 1: parameter delimiter
    let mut pos = 0;
    while pos < b.len() && b[pos] == b' ' {
        pos += 1;
    }
    let pdelim = if b.get(pos) == Some(&b',') {
        pos += 1;
        b','
    } else {
        let c = single_char_delimiter(b, pos, line0, "parameter delimiter")?;
        pos += 3;
        if b.get(pos) != Some(&c) {
            return Err(IgesError::Syntax {
                line: s.line_at(pos),
                expected: format!("Global section: the parameter delimiter {:?}", c as char),
                found: b
                    .get(pos)
                    .map_or("end of data".into(), |x| format!("{:?}", *x as char)),
            });
        }
        pos += 1;
        c
    };
    // field 2: record delimiter
    let rdelim = if b.get(pos) == Some(&pdelim) {
        pos += 1;
        b';'
    } else {
        let c = single_char_delimiter(b, pos, s.line_at(pos), "record delimiter")?;
        pos += 3;
        match b.get(pos) {
            Some(&x) if x == pdelim => pos += 1,
            Some(&x) if x == c => {}
            other => {
                return Err(IgesError::Syntax {
                    line: s.line_at(pos),
                    expected: format!(
                        "Global section: the parameter delimiter {:?}",
                        pdelim as char
                    ),
                    found: other.map_or("end of data".into(), |x| format!("{:?}", *x as char)),
                })
            }
        }
        c
    };
    if pdelim == rdelim {
        return Err(IgesError::Syntax {
            line: line0,
            expected: "Global section: different parameter and record delimiters".into(),
            found: format!("{:?} for both", pdelim as char),
        });
    }
    let params = if b.get(pos) == Some(&rdelim) {
        Vec::new()
    } else {
        tokenize(&s, pos, pdelim, rdelim, "Global section")?
    };
    // params[0] is field 3
    let last_line = records.last().map_or(line0, |r| r.line);
    let get = |field: usize| params.get(field - 3);
    let string = |field: usize, name: &str| -> Result<String, IgesError> {
        match get(field) {
            None => Ok(String::new()),
            Some(p) => p
                .as_str()
                .map(str::to_string)
                .ok_or_else(|| IgesError::Syntax {
                    line: p.line,
                    expected: format!("Global field {field} ({name}): a Hollerith string"),
                    found: p.describe(),
                }),
        }
    };
    let int = |field: usize, name: &str, default: i64| -> Result<i64, IgesError> {
        match get(field) {
            None => Ok(default),
            Some(p) if p.value == ParamValue::Empty => Ok(default),
            Some(p) => p.as_int().ok_or_else(|| IgesError::Syntax {
                line: p.line,
                expected: format!("Global field {field} ({name}): an integer"),
                found: p.describe(),
            }),
        }
    };
    let real = |field: usize, name: &str, default: f64| -> Result<f64, IgesError> {
        match get(field) {
            None => Ok(default),
            Some(p) if p.value == ParamValue::Empty => Ok(default),
            Some(p) => p.as_real().ok_or_else(|| IgesError::Syntax {
                line: p.line,
                expected: format!("Global field {field} ({name}): a real number"),
                found: p.describe(),
            }),
        }
    };
    let _ = last_line;
    let max_coordinate = real(20, "maximum coordinate value", 0.0)?;
    Ok(GlobalSection {
        parameter_delimiter: pdelim as char,
        record_delimiter: rdelim as char,
        product_id_sender: string(3, "product ID of the sender")?,
        file_name: string(4, "file name")?,
        native_system_id: string(5, "native system ID")?,
        preprocessor_version: string(6, "preprocessor version")?,
        integer_bits: int(7, "integer bits", 0)?,
        single_precision_magnitude: int(8, "single precision magnitude", 0)?,
        single_precision_significance: int(9, "single precision significance", 0)?,
        double_precision_magnitude: int(10, "double precision magnitude", 0)?,
        double_precision_significance: int(11, "double precision significance", 0)?,
        product_id_receiver: string(12, "product ID of the receiver")?,
        model_space_scale: real(13, "model space scale", 1.0)?,
        units_flag: int(14, "units flag", 1)?,
        units_name: string(15, "units name")?,
        max_line_weight_gradations: int(16, "line weight gradations", 1)?,
        max_line_weight: real(17, "maximum line weight", 0.0)?,
        date: string(18, "date of generation")?,
        min_resolution: real(19, "minimum resolution", 0.0)?,
        max_coordinate: (max_coordinate != 0.0).then_some(max_coordinate),
        author: string(21, "author")?,
        organization: string(22, "organization")?,
        version: int(23, "version flag", 3)?,
        drafting_standard: int(24, "drafting standard", 0)?,
        modified_date: string(25, "date of modification")?,
        application_protocol: string(26, "application protocol")?,
    })
}

// ---------------------------------------------------------------------------------------------
// Directory Entry section
// ---------------------------------------------------------------------------------------------

/// The fixed fields of one Directory Entry pair.
#[derive(Debug, Clone, PartialEq)]
pub struct DirectoryEntry {
    /// Sequence number of the first record (odd): the entity's DE pointer.
    pub de: u32,
    /// File line of the first record.
    pub line: usize,
    pub entity_type: i32,
    /// Sequence number of the first Parameter Data record.
    pub parameter_pointer: u32,
    pub structure: i64,
    pub line_font: i64,
    pub level: i64,
    pub view: i64,
    /// DE pointer of a 124 transformation matrix (0: none).
    pub transform: u32,
    pub label_display: i64,
    /// Status number: blank status, subordinate switch, entity use flag, hierarchy.
    pub status: [u8; 4],
    pub line_weight: i64,
    pub color: i64,
    /// Number of Parameter Data records.
    pub parameter_line_count: u32,
    pub form: i32,
    pub label: String,
    pub subscript: i64,
}

fn de_field<T: std::str::FromStr>(
    r: &Record<'_>,
    k: usize,
    name: &str,
    expected: &str,
) -> Result<T, IgesError> {
    let f = r.cols(8 * k - 7, 8 * k);
    let t = f.trim();
    let t = if t.is_empty() { "0" } else { t };
    t.parse::<T>().map_err(|_| IgesError::Syntax {
        line: r.line,
        expected: format!(
            "Directory Entry field {name} (columns {}-{}): {expected}",
            8 * k - 7,
            8 * k
        ),
        found: format!("{f:?}"),
    })
}

/// Parses all Directory Entry pairs.
pub(crate) fn parse_directory(records: &[Record<'_>]) -> Result<Vec<DirectoryEntry>, IgesError> {
    let mut out = Vec::with_capacity(records.len() / 2);
    for (i, pair) in records.chunks_exact(2).enumerate() {
        let (a, b) = (&pair[0], &pair[1]);
        let de = (2 * i + 1) as u32;
        let entity_type: i32 = de_field(a, 1, "1 (entity type)", "an integer")?;
        let entity_type2: i32 = de_field(b, 1, "11 (entity type)", "an integer")?;
        if entity_type2 != entity_type {
            return Err(IgesError::Syntax {
                line: b.line,
                expected: format!(
                    "Directory Entry field 11 = entity type {entity_type} (as in field 1)"
                ),
                found: format!("{entity_type2}"),
            });
        }
        let status_text = a.cols(65, 72);
        let mut status = [0u8; 4];
        for (k, s) in status.iter_mut().enumerate() {
            let t = status_text[2 * k..2 * k + 2].trim();
            *s = if t.is_empty() {
                0
            } else {
                t.parse().map_err(|_| IgesError::Syntax {
                    line: a.line,
                    expected: "Directory Entry field 9 (status, columns 65-72): 8 digits".into(),
                    found: format!("{status_text:?}"),
                })?
            };
        }
        let transform: i64 = de_field(a, 7, "7 (transformation matrix)", "an integer")?;
        if transform < 0 || transform > u32::MAX as i64 {
            return Err(IgesError::Syntax {
                line: a.line,
                expected: "Directory Entry field 7 (transformation matrix): a DE pointer >= 0"
                    .into(),
                found: format!("{transform}"),
            });
        }
        out.push(DirectoryEntry {
            de,
            line: a.line,
            entity_type,
            parameter_pointer: de_field(a, 2, "2 (parameter data pointer)", "a positive integer")?,
            structure: de_field(a, 3, "3 (structure)", "an integer")?,
            line_font: de_field(a, 4, "4 (line font pattern)", "an integer")?,
            level: de_field(a, 5, "5 (level)", "an integer")?,
            view: de_field(a, 6, "6 (view)", "an integer")?,
            transform: transform as u32,
            label_display: de_field(a, 8, "8 (label display)", "an integer")?,
            status,
            line_weight: de_field(b, 2, "12 (line weight)", "an integer")?,
            color: de_field(b, 3, "13 (color)", "an integer")?,
            parameter_line_count: de_field(
                b,
                4,
                "14 (parameter line count)",
                "a positive integer",
            )?,
            form: de_field(b, 5, "15 (form number)", "an integer")?,
            label: b.cols(57, 64).trim().to_string(),
            subscript: de_field(b, 9, "19 (entity subscript)", "an integer")?,
        });
    }
    Ok(out)
}
