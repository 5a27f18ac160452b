//! Where the bytes of binary data come from: raw appended bytes, or base64 text decoded
//! group by group.

/// Where the bytes of an array come from.
pub(super) trait ByteSource {
    /// The next `n` bytes.
    fn take(&mut self, n: usize) -> Result<Vec<u8>, String>;
    /// No more bytes than this are left.
    fn left_upper_bound(&self) -> usize;
}

pub(super) struct RawSource<'a> {
    pub(super) data: &'a [u8],
    pub(super) pos: usize,
}

impl ByteSource for RawSource<'_> {
    fn take(&mut self, n: usize) -> Result<Vec<u8>, String> {
        let end = self.pos.checked_add(n).filter(|&e| e <= self.data.len());
        match end {
            Some(end) => {
                let out = self.data[self.pos..end].to_vec();
                self.pos = end;
                Ok(out)
            }
            None => Err(format!(
                "unexpected end of the appended data (needed {n} more bytes, {} left)",
                self.data.len() - self.pos
            )),
        }
    }

    fn left_upper_bound(&self) -> usize {
        self.data.len() - self.pos
    }
}

/// Base64 text decoded group by group: each group of four characters gives one to three
/// bytes (padding `=` ends a group early, and may appear in the middle of the text, where
/// VTK encodes a header and its data separately). Whitespace is skipped; decoding stops at
/// the first `<` or at the end of the input.
pub(super) struct Base64Source<'a> {
    text: &'a [u8],
    pos: usize,
    /// Decoded but not yet taken.
    pending: Vec<u8>,
}

impl<'a> Base64Source<'a> {
    pub(super) fn new(text: &'a [u8]) -> Self {
        Base64Source {
            text,
            pos: 0,
            pending: Vec::new(),
        }
    }

    /// Decodes the next group into `pending`; false at the end of the data.
    fn next_group(&mut self) -> Result<bool, String> {
        let mut group = [0u8; 4];
        let mut n = 0;
        while n < 4 {
            let Some(&c) = self.text.get(self.pos) else {
                break;
            };
            if c == b'<' {
                break;
            }
            self.pos += 1;
            if c.is_ascii_whitespace() {
                continue;
            }
            group[n] = c;
            n += 1;
        }
        if n == 0 {
            return Ok(false);
        }
        if n < 4 {
            return Err(format!(
                "base64 data ends in an incomplete group of {n} characters"
            ));
        }
        let value = |c: u8| -> Result<u32, String> {
            Ok(match c {
                b'A'..=b'Z' => c - b'A',
                b'a'..=b'z' => c - b'a' + 26,
                b'0'..=b'9' => c - b'0' + 52,
                b'+' => 62,
                b'/' => 63,
                _ => return Err(format!("'{}' is not a base64 character", c as char)),
            } as u32)
        };
        let bytes = match (group[2], group[3]) {
            (b'=', b'=') => 1,
            (_, b'=') => 2,
            (b'=', _) => return Err("misplaced base64 padding".into()),
            _ => 3,
        };
        let mut v = 0u32;
        for (i, &c) in group.iter().enumerate() {
            v |= if i > bytes { 0 } else { value(c)? } << (18 - 6 * i);
        }
        let decoded = [(v >> 16) as u8, (v >> 8) as u8, v as u8];
        self.pending.extend_from_slice(&decoded[..bytes]);
        Ok(true)
    }
}

impl ByteSource for Base64Source<'_> {
    fn take(&mut self, n: usize) -> Result<Vec<u8>, String> {
        if n > self.left_upper_bound() {
            return Err(format!(
                "unexpected end of the base64 data (needed {n} more bytes, at most {} left)",
                self.left_upper_bound()
            ));
        }
        while self.pending.len() < n {
            if !self.next_group()? {
                return Err(format!(
                    "unexpected end of the base64 data (needed {n} more bytes, {} left)",
                    self.pending.len()
                ));
            }
        }
        let rest = self.pending.split_off(n);
        Ok(std::mem::replace(&mut self.pending, rest))
    }

    fn left_upper_bound(&self) -> usize {
        self.pending.len() + (self.text.len() - self.pos.min(self.text.len())) / 4 * 3 + 3
    }
}
