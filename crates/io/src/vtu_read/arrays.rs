//! Data arrays as numbers: ASCII text, or binary values of any VTK numeric type in
//! either byte order.

use crate::xml::XmlElement;

use super::failure::{fail, Fail, R};
use super::file::VtkFile;

impl VtkFile<'_, '_> {
    /// Values of a numeric array as f64, `expected` of them.
    pub(super) fn floats(&self, array: &XmlElement, expected: usize) -> R<Vec<f64>> {
        let ty = array.attribute("type").unwrap_or("");
        let values: Vec<f64> = if array.attribute("format").unwrap_or("ascii") == "ascii" {
            let text = array.text_content(self.bytes);
            let text: &[u8] = &text;
            let mut out = Vec::with_capacity(expected.min(text.len() / 2 + 1));
            for token in text
                .split(|c| c.is_ascii_whitespace())
                .filter(|t| !t.is_empty())
            {
                match std::str::from_utf8(token)
                    .ok()
                    .and_then(|t| t.parse::<f64>().ok())
                {
                    Some(v) => out.push(v),
                    None => {
                        return fail(
                            array,
                            format!(
                                "DataArray {}: '{}' is not a number",
                                array_name(array),
                                String::from_utf8_lossy(token)
                            ),
                        )
                    }
                }
            }
            out
        } else {
            let bytes = self.raw_bytes(array)?;
            let big = self.big_endian;
            match ty {
                "Float64" => convert::<8, _>(&bytes, big, f64::from_le_bytes, f64::from_be_bytes),
                "Float32" => convert::<4, _>(
                    &bytes,
                    big,
                    |b| f64::from(f32::from_le_bytes(b)),
                    |b| f64::from(f32::from_be_bytes(b)),
                ),
                _ => Some(
                    self.binary_integers(array, &bytes)?
                        .into_iter()
                        .map(|v| v as f64)
                        .collect(),
                ),
            }
            .ok_or_else(|| Fail {
                offset: Some(array.offset),
                message: format!(
                    "DataArray {}: {} bytes are not a whole number of {ty} values",
                    array_name(array),
                    bytes.len()
                ),
            })?
        };
        if values.len() != expected {
            return fail(
                array,
                format!(
                    "DataArray {} has {} values, expected {expected}",
                    array_name(array),
                    values.len()
                ),
            );
        }
        Ok(values)
    }

    /// Values of an integer array, `expected` of them if given.
    pub(super) fn integers(&self, array: &XmlElement, expected: Option<usize>) -> R<Vec<i64>> {
        let values = if array.attribute("format").unwrap_or("ascii") == "ascii" {
            let text = array.text_content(self.bytes);
            let text: &[u8] = &text;
            let mut out = Vec::new();
            for token in text
                .split(|c| c.is_ascii_whitespace())
                .filter(|t| !t.is_empty())
            {
                match std::str::from_utf8(token)
                    .ok()
                    .and_then(|t| t.parse::<i64>().ok())
                {
                    Some(v) => out.push(v),
                    None => {
                        return fail(
                            array,
                            format!(
                                "DataArray {}: '{}' is not an integer",
                                array_name(array),
                                String::from_utf8_lossy(token)
                            ),
                        )
                    }
                }
            }
            out
        } else {
            let bytes = self.raw_bytes(array)?;
            self.binary_integers(array, &bytes)?
        };
        if let Some(n) = expected {
            if values.len() != n {
                return fail(
                    array,
                    format!(
                        "DataArray {} has {} values, expected {n}",
                        array_name(array),
                        values.len()
                    ),
                );
            }
        }
        Ok(values)
    }

    fn binary_integers(&self, array: &XmlElement, bytes: &[u8]) -> R<Vec<i64>> {
        let ty = array.attribute("type").unwrap_or("");
        let big = self.big_endian;
        let values = match ty {
            "Int8" => convert::<1, _>(
                bytes,
                big,
                |b| i64::from(i8::from_le_bytes(b)),
                |b| i64::from(i8::from_be_bytes(b)),
            ),
            "UInt8" => convert::<1, _>(bytes, big, |b| i64::from(b[0]), |b| i64::from(b[0])),
            "Int16" => convert::<2, _>(
                bytes,
                big,
                |b| i64::from(i16::from_le_bytes(b)),
                |b| i64::from(i16::from_be_bytes(b)),
            ),
            "UInt16" => convert::<2, _>(
                bytes,
                big,
                |b| i64::from(u16::from_le_bytes(b)),
                |b| i64::from(u16::from_be_bytes(b)),
            ),
            "Int32" => convert::<4, _>(
                bytes,
                big,
                |b| i64::from(i32::from_le_bytes(b)),
                |b| i64::from(i32::from_be_bytes(b)),
            ),
            "UInt32" => convert::<4, _>(
                bytes,
                big,
                |b| i64::from(u32::from_le_bytes(b)),
                |b| i64::from(u32::from_be_bytes(b)),
            ),
            "Int64" => convert::<8, _>(bytes, big, i64::from_le_bytes, i64::from_be_bytes),
            // Values beyond i64::MAX become negative and are rejected as ids and offsets.
            "UInt64" => convert::<8, _>(
                bytes,
                big,
                |b| u64::from_le_bytes(b) as i64,
                |b| u64::from_be_bytes(b) as i64,
            ),
            other => {
                return fail(
                    array,
                    format!(
                        "DataArray {} has type {other:?}, expected an integer type",
                        array_name(array)
                    ),
                )
            }
        };
        values.ok_or_else(|| Fail {
            offset: Some(array.offset),
            message: format!(
                "DataArray {}: {} bytes are not a whole number of {ty} values",
                array_name(array),
                bytes.len()
            ),
        })
    }
}

pub(super) fn array_name<'b>(array: &'b XmlElement) -> &'b str {
    array.attribute("Name").unwrap_or("(unnamed)")
}

/// Splits `bytes` into `N`-byte values; None if the length is not a multiple of `N`.
fn convert<const N: usize, T>(
    bytes: &[u8],
    big_endian: bool,
    le: impl Fn([u8; N]) -> T,
    be: impl Fn([u8; N]) -> T,
) -> Option<Vec<T>> {
    let chunks = bytes.chunks_exact(N);
    if !chunks.remainder().is_empty() {
        return None;
    }
    Some(
        chunks
            .map(|c| {
                let mut a = [0u8; N];
                a.copy_from_slice(c);
                if big_endian {
                    be(a)
                } else {
                    le(a)
                }
            })
            .collect(),
    )
}
