//! Reading an IGES file: its sections split, the Global section and Directory Entries read,
//! and every entity's Parameter Data tokenized and read into its typed record.

use std::path::Path;

use super::error::IgesError;
use super::model::{IgesEntity, IgesModel};
use super::params::ParamValue;
use super::references::validate;
use super::{directory, entity_parser, global, param_reader, params, sections};

/// Reads and parses an IGES file.
pub fn read_iges(path: impl AsRef<Path>) -> Result<IgesModel, IgesError> {
    let path = path.as_ref();
    let bytes = std::fs::read(path).map_err(|source| IgesError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    // non-ASCII bytes are reported with their line by the parser
    parse_iges(&String::from_utf8_lossy(&bytes))
}

/// Parses the text of an IGES 5.3 file (fixed ASCII form).
pub fn parse_iges(text: &str) -> Result<IgesModel, IgesError> {
    let secs = sections::split_sections(text)?;
    let global = global::parse_global(&secs.global)?;
    let directory = directory::parse_directory(&secs.directory)?;
    let pdelim = global.parameter_delimiter as u8;
    let rdelim = global.record_delimiter as u8;
    let p = &secs.parameter;
    let mut entities = Vec::with_capacity(directory.len());
    let mut references = Vec::new();
    for de in directory {
        let first = de.parameter_pointer as usize;
        let count = de.parameter_line_count as usize;
        let p_end = p.len();
        if first == 0 || count == 0 || first - 1 + count > p_end {
            return Err(IgesError::Syntax {
                line: de.line,
                expected: format!(
                    "entity type {} (DE {}): parameter data records {}..{} (pointer, line count)",
                    de.entity_type,
                    de.de,
                    first,
                    (first + count).saturating_sub(1)
                ),
                found: format!("a Parameter Data section of {p_end} records"),
            });
        }
        let records = &p[first - 1..first - 1 + count];
        for r in records {
            let back = r.cols(66, 72);
            if back.trim().parse::<u32>().ok() != Some(de.de) {
                return Err(IgesError::BackPointer {
                    line: r.line,
                    expected: de.de,
                    found: back.to_string(),
                });
            }
        }
        let stream = params::Stream::from_records(records, 1, 64);
        let what = format!("entity type {} (DE {})", de.entity_type, de.de);
        let params = params::tokenize(&stream, 0, pdelim, rdelim, &what)?;
        let end_line = records[count - 1].line;
        let type_param = &params[0];
        if type_param.as_int() != Some(de.entity_type as i64)
            || type_param.value == ParamValue::Empty
        {
            return Err(IgesError::Parameter {
                line: type_param.line,
                de: de.de,
                entity_type: de.entity_type,
                index: 0,
                name: "entity type number",
                expected: "the entity type of the Directory Entry",
                found: type_param.describe(),
            });
        }
        let mut reader = param_reader::Reader::new(&params[1..], de.de, de.entity_type, end_line);
        let kind = entity_parser::parse_entity(de.entity_type, &mut reader)?;
        references.extend(reader.refs.iter().map(|r| (*r, de.de, de.entity_type)));
        entities.push(IgesEntity {
            de: de.de,
            kind,
            form: de.form,
            transform: (de.transform != 0).then_some(de.transform),
            line: de.line,
            parameter_line: records[0].line,
            directory: de,
        });
    }
    let start = secs
        .start
        .iter()
        .map(|r| r.cols(1, 72).trim_end().to_string())
        .collect();
    let model = IgesModel {
        start,
        global,
        entities,
    };
    validate(&model, &references)?;
    Ok(model)
}
