//! The Global section (IGES 5.3 §2.2.4): its delimiters, units, model scale and resolution.

use super::error::IgesError;
use super::params::{tokenize, Param, ParamValue, Stream};
use super::sections::Record;

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
    let string = |field: usize, name: &str| {
        let read = |p: &Param| p.as_str().map(str::to_string);
        global_field(
            &params,
            field,
            name,
            String::new(),
            read,
            "a Hollerith string",
        )
    };
    let int = |field: usize, name: &str, default: i64| {
        global_field(&params, field, name, default, Param::as_int, "an integer")
    };
    let real = |field: usize, name: &str, default: f64| {
        global_field(
            &params,
            field,
            name,
            default,
            Param::as_real,
            "a real number",
        )
    };
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

/// Global field `field` (1-based; `params` begins with field 3) as read by `read`, which
/// must give a `kind`; `default` when the section ends before it or it is defaulted.
fn global_field<T>(
    params: &[Param],
    field: usize,
    name: &str,
    default: T,
    read: impl Fn(&Param) -> Option<T>,
    kind: &str,
) -> Result<T, IgesError> {
    match params.get(field - 3) {
        None => Ok(default),
        Some(p) if p.value == ParamValue::Empty => Ok(default),
        Some(p) => read(p).ok_or_else(|| IgesError::Syntax {
            line: p.line,
            expected: format!("Global field {field} ({name}): {kind}"),
            found: p.describe(),
        }),
    }
}
