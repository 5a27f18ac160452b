//! The Directory Entry section: the fixed 8-column fields of each entity's pair of records.

use super::error::IgesError;
use super::sections::Record;

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
