//! The `$MeshFormat` section: MSH version, ASCII or binary, data size.

use super::failure::{fail, R};
use super::parser::{Parser, Version};
use super::tokens::show;

impl Parser<'_> {
    /// `$MeshFormat`: the version (4.1 or 2.0–2.2), ASCII or binary, the data size and, in
    /// binary files, the byte order.
    pub(super) fn mesh_format(&mut self) -> R<()> {
        let input = &mut self.input;
        input.begin_text(|| "the MSH version, file type and data size (e.g. '4.1 0 8')".into())?;
        let loc = input.rec_location();
        let version = match input.token() {
            None => return Err(input.missing("the MSH version".into())),
            Some(b"4.1") => Version::V41,
            Some(b"2" | b"2.0" | b"2.1" | b"2.2") => Version::V2,
            Some(b"4" | b"4.0") => {
                return fail(
                    loc,
                    "MSH version 4.0 is not supported (expected 4.1 or 2.2); re-save the mesh \
                     with Mesh.MshFileVersion = 4.1",
                )
            }
            Some(t) => {
                return fail(
                    loc,
                    format!("unsupported MSH version {} (expected 4.1 or 2.2)", show(t)),
                )
            }
        };
        self.version = version;
        let file_type = input.int(|| "the file type (0 = ASCII, 1 = binary)".into())?;
        let data_size = input.int(|| "the data size".into())?;
        input.end_record(|| "the MSH version, file type and data size".into())?;
        match file_type {
            0 => {}
            1 => {
                let ok = match version {
                    Version::V41 => data_size == 8 || data_size == 4,
                    Version::V2 => data_size == 8,
                };
                if !ok {
                    return fail(
                        loc,
                        format!("unsupported data size {data_size} in a binary file (expected 8)"),
                    );
                }
                input.start_binary(if data_size == 4 { 4 } else { 8 })?;
            }
            _ => {
                return fail(
                    loc,
                    format!("expected file type 0 (ASCII) or 1 (binary), found {file_type}"),
                )
            }
        }
        input.expect_end("MeshFormat", String::new)
    }
}
