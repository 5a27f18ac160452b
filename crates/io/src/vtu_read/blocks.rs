//! The bytes of a binary or appended data array: its size header, and its zlib blocks
//! when compressed.

use std::io::Read;

use crate::xml::XmlElement;

use super::arrays::array_name;
use super::byte_source::{Base64Source, ByteSource, RawSource};
use super::failure::{fail, Fail, R};
use super::file::{HeaderType, VtkFile};

impl VtkFile<'_, '_> {
    /// The decoded bytes of a binary or appended `DataArray`.
    pub(super) fn raw_bytes(&self, array: &XmlElement) -> R<Vec<u8>> {
        let format = array.attribute("format").unwrap_or("ascii");
        let inline;
        let mut source: Box<dyn ByteSource + '_> = match format {
            "binary" => {
                inline = array.text_content(self.bytes);
                Box::new(Base64Source::new(&inline))
            }
            "appended" => {
                let Some((data, base64)) = self.appended else {
                    return fail(
                        array,
                        "format=\"appended\" but the file has no <AppendedData>",
                    );
                };
                let offset = array
                    .attribute("offset")
                    .and_then(|o| o.trim().parse::<usize>().ok())
                    .map_or_else(
                        || fail(array, "appended DataArray without a valid offset"),
                        Ok,
                    )?;
                let Some(at) = data.get(offset..) else {
                    return fail(
                        array,
                        format!(
                            "offset {offset} is beyond the {} bytes of appended data",
                            data.len()
                        ),
                    );
                };
                if base64 {
                    Box::new(Base64Source::new(at))
                } else {
                    Box::new(RawSource { data: at, pos: 0 })
                }
            }
            other => return fail(array, format!("unknown DataArray format {other:?}")),
        };
        self.read_block(source.as_mut()).map_err(|message| Fail {
            offset: Some(array.offset),
            message: format!("DataArray {}: {message}", array_name(array)),
        })
    }

    /// Reads one array (header + data, compressed or not) from a byte source.
    fn read_block(&self, source: &mut dyn ByteSource) -> Result<Vec<u8>, String> {
        let word = match self.header {
            HeaderType::UInt32 => 4,
            HeaderType::UInt64 => 8,
        };
        let read_word = |source: &mut dyn ByteSource| -> Result<u64, String> {
            let b = source.take(word)?;
            let mut v = [0u8; 8];
            if self.big_endian {
                v[8 - word..].copy_from_slice(&b);
                Ok(u64::from_be_bytes(v))
            } else {
                v[..word].copy_from_slice(&b);
                Ok(u64::from_le_bytes(v))
            }
        };
        let too_big = |n: u64| format!("announced size {n} is beyond what the file can hold");
        if !self.zlib {
            let n = read_word(source)?;
            let n = usize::try_from(n).map_err(|_| too_big(n))?;
            if n > source.left_upper_bound() {
                return Err(too_big(n as u64));
            }
            return source.take(n);
        }
        let blocks = read_word(source)?;
        let block_size = read_word(source)?;
        let last_size = read_word(source)?;
        let blocks = usize::try_from(blocks)
            .ok()
            .filter(|&b| b.saturating_mul(word) <= source.left_upper_bound())
            .ok_or_else(|| format!("compression header announces {blocks} blocks"))?;
        let mut compressed = Vec::with_capacity(blocks);
        for _ in 0..blocks {
            compressed.push(read_word(source)?);
        }
        let mut out = Vec::new();
        for (i, &c) in compressed.iter().enumerate() {
            let c = usize::try_from(c)
                .ok()
                .filter(|&c| c <= source.left_upper_bound())
                .ok_or_else(|| too_big(c))?;
            let data = source.take(c)?;
            let expected = if i + 1 == blocks && last_size != 0 {
                last_size
            } else {
                block_size
            };
            let before = out.len();
            flate2::read::ZlibDecoder::new(data.as_slice())
                .take(expected)
                .read_to_end(&mut out)
                .map_err(|e| format!("zlib block {i} of {blocks} does not decompress: {e}"))?;
            if (out.len() - before) as u64 != expected {
                return Err(format!(
                    "zlib block {i} of {blocks} decompresses to {} bytes, the header says {expected}",
                    out.len() - before
                ));
            }
        }
        Ok(out)
    }
}
