//! The IGES 5.3 fixed (ASCII, 80-column) file layout: the records, their section letters
//! (column 73) and sequence numbers (columns 74–80), and the Terminate record's counts.

use super::error::IgesError;

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
