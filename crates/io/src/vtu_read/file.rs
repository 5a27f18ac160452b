//! The `<VTKFile>` element's settings (byte order, header words, compression, version)
//! and where its `<UnstructuredGrid>` and appended data are.

use crate::xml::XmlElement;

use super::failure::{fail, R};

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum HeaderType {
    UInt32,
    UInt64,
}

/// The `VTKFile` element's settings and the appended data block.
pub(super) struct VtkFile<'a, 'x> {
    pub(super) bytes: &'a [u8],
    pub(super) root: &'x XmlElement<'a>,
    pub(super) grid: &'x XmlElement<'a>,
    pub(super) big_endian: bool,
    pub(super) header: HeaderType,
    pub(super) zlib: bool,
    /// Version (major, minor).
    pub(super) version: (u32, u32),
    /// Appended data: its bytes after the `_` marker, and whether base64.
    pub(super) appended: Option<(&'a [u8], bool)>,
}

impl<'a, 'x> VtkFile<'a, 'x> {
    pub(super) fn new(bytes: &'a [u8], root: &'x XmlElement<'a>) -> R<Self> {
        if root.name != "VTKFile" {
            return fail(root, format!("expected <VTKFile>, found <{}>", root.name));
        }
        match root.attribute("type") {
            Some("UnstructuredGrid") => {}
            Some(other) => {
                return fail(
                    root,
                    format!("VTK file type {other} is not supported (expected UnstructuredGrid)"),
                )
            }
            None => return fail(root, "<VTKFile> has no type attribute"),
        }
        let big_endian = match root.attribute("byte_order") {
            None | Some("LittleEndian") => false,
            Some("BigEndian") => true,
            Some(other) => return fail(root, format!("unknown byte_order {other:?}")),
        };
        let header = match root.attribute("header_type") {
            None | Some("UInt32") => HeaderType::UInt32,
            Some("UInt64") => HeaderType::UInt64,
            Some(other) => return fail(root, format!("unknown header_type {other:?}")),
        };
        let zlib = match root.attribute("compressor") {
            None | Some("") => false,
            Some("vtkZLibDataCompressor") => true,
            Some(other) => {
                return fail(
                    root,
                    format!(
                        "compressor {other} is not supported (only vtkZLibDataCompressor); \
                         re-save the file with zlib compression or none"
                    ),
                )
            }
        };
        let version = root
            .attribute("version")
            .and_then(|v| {
                let mut parts = v.trim().splitn(2, '.');
                let major = parts.next()?.parse().ok()?;
                let minor = parts.next().map_or(Some(0), |m| m.parse().ok())?;
                Some((major, minor))
            })
            .unwrap_or((0, 1));
        let Some(grid) = root.child("UnstructuredGrid") else {
            return fail(root, "<VTKFile> has no <UnstructuredGrid>");
        };
        let appended = match root.child("AppendedData") {
            None => None,
            Some(a) => {
                let base64 = match a.attribute("encoding") {
                    Some("raw") => false,
                    Some("base64") => true,
                    other => {
                        return fail(
                            a,
                            format!("<AppendedData> encoding {other:?} (expected raw or base64)"),
                        )
                    }
                };
                let content = bytes.get(a.content.clone()).unwrap_or(&[]);
                let Some(k) = content.iter().position(|&c| c == b'_') else {
                    return fail(a, "<AppendedData> has no '_' marker before its data");
                };
                Some((&content[k + 1..], base64))
            }
        };
        Ok(VtkFile {
            bytes,
            root,
            grid,
            big_endian,
            header,
            zlib,
            version,
            appended,
        })
    }
}
