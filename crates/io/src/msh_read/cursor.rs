//! Reading an MSH file record by record: a record is a text line (ASCII files, and the
//! header lines of binary ones) or a run of binary values (`int`, `size_t`, `double`, in the
//! file's byte order). Integers, counts and reals are read the same way from either, so the
//! section parsers need not know which the file is; errors name the line (ASCII) or the
//! byte offset (binary).

use super::failure::{eof_fail, fail, Fail, R};
use super::tokens::{is_blank, parse_float, parse_int, parse_uint, show, trim};
use crate::error::Location;

/// The read position in an MSH file and the record being read.
pub(super) struct Cursor<'a> {
    b: &'a [u8],
    /// Read position.
    pos: usize,
    /// 1-based number of the line holding `pos` (meaningful in ASCII files).
    line: usize,
    binary: bool,
    /// Binary data is big-endian.
    swap: bool,
    /// Bytes of a `size_t` in binary MSH 4.1.
    size_t: usize,
    // The current record: one text line, or a position in binary data.
    rec: &'a [u8],
    rec_i: usize,
    rec_text: bool,
    rec_loc: Location,
    /// The current text record is the last line and has no newline (truncated file).
    rec_last: bool,
    /// Start of the last binary value read.
    field_at: usize,
}

impl<'a> Cursor<'a> {
    /// At the start of `b` (after a UTF-8 byte order mark, if any), reading text.
    pub(super) fn new(b: &'a [u8]) -> Self {
        let start = if b.starts_with(&[0xef, 0xbb, 0xbf]) {
            3
        } else {
            0
        };
        Cursor {
            b,
            pos: start,
            line: 1,
            binary: false,
            swap: false,
            size_t: 8,
            rec: &[],
            rec_i: 0,
            rec_text: true,
            rec_loc: Location::Line(1),
            rec_last: false,
            field_at: 0,
        }
    }

    /// The data after the `$MeshFormat` line is binary.
    pub(super) fn is_binary(&self) -> bool {
        self.binary
    }

    /// Bytes of a binary `size_t`.
    pub(super) fn size_t(&self) -> usize {
        self.size_t
    }

    /// Switches to binary data with `size_t`-byte counts, reading the byte order from the
    /// integer 1 that follows the `$MeshFormat` line.
    pub(super) fn start_binary(&mut self, size_t: usize) -> R<()> {
        self.size_t = size_t;
        self.binary = true;
        let at = self.pos;
        let one = self.take::<4>(|| {
            "the binary integer 1 (endianness check) after the $MeshFormat line".into()
        })?;
        if u32::from_le_bytes(one) == 1 {
            self.swap = false;
        } else if u32::from_be_bytes(one) == 1 {
            self.swap = true;
        } else {
            return fail(
                Location::Byte(at as u64),
                format!(
                    "expected the binary integer 1 (endianness check) after the \
                     $MeshFormat line, found bytes {one:02x?}"
                ),
            );
        }
        Ok(())
    }

    /// The rest of the current text record, trimmed; the record is then used up.
    pub(super) fn rest_of_record(&mut self) -> &'a [u8] {
        let rest = trim(self.rec.get(self.rec_i..).unwrap_or(&[]));
        self.rec_i = self.rec.len();
        rest
    }

    /// The current text record is the file's last line, cut off without a newline.
    pub(super) fn is_last_line(&self) -> bool {
        self.rec_last
    }

    /// Bytes left after the read position.
    fn remaining(&self) -> usize {
        self.b.len().saturating_sub(self.pos)
    }

    /// Location of `byte`: its offset in binary files, the current line in ASCII ones.
    fn loc_at(&self, byte: usize) -> Location {
        if self.binary {
            Location::Byte(byte as u64)
        } else {
            Location::Line(self.line)
        }
    }

    /// Skips blank lines and leading blanks; false at the end of the input.
    fn skip_blank_lines(&mut self) -> bool {
        while let Some(&c) = self.b.get(self.pos) {
            if c == b'\n' {
                self.line += 1;
            } else if !is_blank(c) {
                return true;
            }
            self.pos += 1;
        }
        false
    }

    /// Consumes the next non-blank line: its location, trimmed text, and whether it ended
    /// with a newline.
    pub(super) fn next_line(&mut self) -> Option<(Location, &'a [u8], bool)> {
        if !self.skip_blank_lines() {
            return None;
        }
        let start = self.pos;
        let loc = self.loc_at(start);
        let rest = self.b.get(start..).unwrap_or(&[]);
        let (text, terminated) = match rest.iter().position(|&c| c == b'\n') {
            Some(k) => {
                self.pos = start + k + 1;
                self.line += 1;
                (&rest[..k], true)
            }
            None => {
                self.pos = self.b.len();
                (rest, false)
            }
        };
        Some((loc, trim(text), terminated))
    }

    /// Location of the next line if it starts a section (`$…`), in text parts of the file.
    pub(super) fn peek_dollar(&mut self) -> Option<Location> {
        if self.skip_blank_lines() && self.b.get(self.pos) == Some(&b'$') {
            Some(self.loc_at(self.pos))
        } else {
            None
        }
    }

    /// Starts the next of the records a section announced ([`Cursor::begin`]): a section
    /// header (`$…`) in its place means the section holds fewer, the error `fewer` (not
    /// looked for in binary data, where a `$` byte may be part of a value).
    pub(super) fn begin_announced(
        &mut self,
        fewer: impl FnOnce() -> String,
        what: impl FnOnce() -> String,
    ) -> R<()> {
        if !self.binary {
            if let Some(loc) = self.peek_dollar() {
                return fail(loc, fewer());
            }
        }
        self.begin(what)
    }

    /// Starts a record that is a text line (also in binary files).
    pub(super) fn begin_text(&mut self, what: impl FnOnce() -> String) -> R<()> {
        match self.next_line() {
            None => Err(eof_fail(format!(
                "unexpected end of file: expected {}",
                what()
            ))),
            Some((loc, text, terminated)) => {
                if text.first() == Some(&b'$') {
                    return fail(loc, format!("expected {}, found {}", what(), show(text)));
                }
                self.rec = text;
                self.rec_i = 0;
                self.rec_text = true;
                self.rec_loc = loc;
                self.rec_last = !terminated;
                Ok(())
            }
        }
    }

    /// Starts a record: a text line in ASCII files, the next bytes in binary ones.
    pub(super) fn begin(&mut self, what: impl FnOnce() -> String) -> R<()> {
        if self.binary {
            self.rec_text = false;
            self.rec_loc = Location::Byte(self.pos as u64);
            Ok(())
        } else {
            self.begin_text(what)
        }
    }

    /// Location of the current record.
    pub(super) fn rec_location(&self) -> Location {
        self.rec_loc
    }

    /// Location of the value just read.
    pub(super) fn value_loc(&self) -> Location {
        if self.rec_text {
            self.rec_loc
        } else {
            Location::Byte(self.field_at as u64)
        }
    }

    /// The next blank-separated token of the current text record.
    pub(super) fn token(&mut self) -> Option<&'a [u8]> {
        let r = self.rec;
        let mut i = self.rec_i;
        while r.get(i).is_some_and(|&c| is_blank(c)) {
            i += 1;
        }
        let start = i;
        while r.get(i).is_some_and(|&c| !is_blank(c)) {
            i += 1;
        }
        self.rec_i = i;
        (i > start).then(|| &r[start..i])
    }

    /// How many tokens the current text record has left (`None` in binary data).
    pub(super) fn tokens_left(&self) -> Option<usize> {
        if !self.rec_text {
            return None;
        }
        let rest = self.rec.get(self.rec_i..).unwrap_or(&[]);
        Some(
            rest.split(|&c| is_blank(c))
                .filter(|t| !t.is_empty())
                .count(),
        )
    }

    /// The value `what` is missing: the line ended (or the file, if this is its cut-off last
    /// line).
    pub(super) fn missing(&self, what: String) -> Fail {
        if self.rec_last {
            eof_fail(format!("unexpected end of file: expected {what}"))
        } else {
            Fail::at(self.rec_loc, format!("expected {what}, found end of line"))
        }
    }

    /// Token `tok` is not the value `what`.
    fn bad(&self, what: String, tok: &[u8]) -> Fail {
        // A garbled last token of an unterminated last line is a cut-off file.
        if self.rec_last && self.rec_i >= self.rec.len() {
            return eof_fail(format!("unexpected end of file: expected {what}"));
        }
        Fail::at(
            self.rec_loc,
            format!("expected {what}, found {}", show(tok)),
        )
    }

    /// The next `N` bytes of binary data.
    fn take<const N: usize>(&mut self, what: impl FnOnce() -> String) -> R<[u8; N]> {
        self.field_at = self.pos;
        let bytes = self
            .pos
            .checked_add(N)
            .and_then(|end| self.b.get(self.pos..end))
            .and_then(|s| <[u8; N]>::try_from(s).ok());
        match bytes {
            Some(a) => {
                self.pos += N;
                Ok(a)
            }
            None => Err(eof_fail(format!(
                "unexpected end of file: expected {}",
                what()
            ))),
        }
    }

    /// The next token of the current text record, read by `parse`.
    fn text_value<T>(
        &mut self,
        what: impl FnOnce() -> String,
        parse: fn(&[u8]) -> Option<T>,
    ) -> R<T> {
        match self.token() {
            None => Err(self.missing(what())),
            Some(t) => parse(t).ok_or_else(|| self.bad(what(), t)),
        }
    }

    /// The next `N` bytes of binary data as a number in the file's byte order.
    fn binary_value<const N: usize, T>(
        &mut self,
        what: impl FnOnce() -> String,
        from_le: fn([u8; N]) -> T,
        from_be: fn([u8; N]) -> T,
    ) -> R<T> {
        let a = self.take::<N>(what)?;
        Ok(if self.swap { from_be(a) } else { from_le(a) })
    }

    /// An integer: a token, or a binary 4-byte `int`.
    pub(super) fn int(&mut self, what: impl FnOnce() -> String) -> R<i64> {
        if self.rec_text {
            self.text_value(what, parse_int)
        } else {
            self.binary_value(what, i32::from_le_bytes, i32::from_be_bytes)
                .map(i64::from)
        }
    }

    /// A 32-bit integer (tags).
    pub(super) fn int32(&mut self, what: impl FnOnce() -> String + Clone) -> R<i32> {
        let v = self.int(what.clone())?;
        i32::try_from(v).or_else(|_| {
            fail(
                self.value_loc(),
                format!("expected {} (a 32-bit integer), found {v}", what()),
            )
        })
    }

    /// A non-negative count or tag: a token, or a binary `size_t`.
    pub(super) fn size(&mut self, what: impl FnOnce() -> String) -> R<u64> {
        if self.rec_text {
            self.text_value(what, parse_uint)
        } else if self.size_t == 4 {
            self.binary_value(what, u32::from_le_bytes, u32::from_be_bytes)
                .map(u64::from)
        } else {
            self.binary_value(what, u64::from_le_bytes, u64::from_be_bytes)
        }
    }

    /// A real: a token, or a binary 8-byte `double`.
    pub(super) fn float(&mut self, what: impl FnOnce() -> String) -> R<f64> {
        if self.rec_text {
            self.text_value(what, parse_float)
        } else {
            self.binary_value(what, f64::from_le_bytes, f64::from_be_bytes)
        }
    }

    /// Ends a record: a text line must hold nothing more.
    pub(super) fn end_record(&mut self, what: impl FnOnce() -> String) -> R<()> {
        if self.rec_text {
            if let Some(t) = self.token() {
                return fail(
                    self.rec_loc,
                    format!("expected end of line after {}, found {}", what(), show(t)),
                );
            }
        }
        Ok(())
    }

    /// In binary data, fails early when `count` items of `each` bytes cannot fit in the rest
    /// of the file (so that no absurd count is looped over or allocated for).
    pub(super) fn check_room(&self, count: u64, each: u64, what: impl FnOnce() -> String) -> R<()> {
        let rem = self.remaining() as u64;
        if self.binary && count.saturating_mul(each) > rem {
            return Err(eof_fail(format!(
                "unexpected end of file: {} needs {} bytes, only {rem} remain",
                what(),
                count.saturating_mul(each)
            )));
        }
        Ok(())
    }

    /// Capacity to reserve for `count` items of at least `each` bytes in the rest of the file.
    pub(super) fn capacity(&self, count: u64, each: usize) -> usize {
        let fit = self.remaining() / each.max(1);
        usize::try_from(count).map_or(fit, |c| c.min(fit))
    }

    /// Reads the `$End<name>` line closing a section.
    pub(super) fn expect_end(&mut self, name: &str, context: impl FnOnce() -> String) -> R<()> {
        match self.next_line() {
            None => Err(eof_fail(format!(
                "unexpected end of file: expected $End{name}"
            ))),
            Some((loc, text, _)) => {
                if text.strip_prefix(b"$End") == Some(name.as_bytes()) {
                    Ok(())
                } else {
                    fail(
                        loc,
                        format!("expected $End{name}{}, found {}", context(), show(text)),
                    )
                }
            }
        }
    }

    /// Skips a section this reader does not need, up to its `$End<name>` line (which must
    /// start a line; binary data is not interpreted).
    pub(super) fn skip_section(&mut self, name: &[u8], loc: Location) -> R<()> {
        let mut end = b"$End".to_vec();
        end.extend_from_slice(name);
        let start = self.pos;
        let mut i = start;
        loop {
            let Some(off) = self
                .b
                .get(i..)
                .and_then(|r| r.iter().position(|&c| c == b'$'))
            else {
                return Err(Fail {
                    location: loc,
                    message: format!(
                        "unexpected end of file: section ${} has no ${}",
                        String::from_utf8_lossy(name),
                        String::from_utf8_lossy(&end[1..])
                    ),
                    eof: true,
                });
            };
            let p = i + off;
            let q = p + end.len();
            let at_line_start = p == start || matches!(self.b.get(p - 1), Some(b'\n'));
            let matches = self.b.get(p..q) == Some(end.as_slice());
            let ends_line = matches!(self.b.get(q), None | Some(b'\n' | b'\r' | b' ' | b'\t'));
            if at_line_start && matches && ends_line {
                let skipped = self.b.get(start..p).unwrap_or(&[]);
                self.line += skipped.iter().filter(|&&c| c == b'\n').count();
                self.pos = p;
                // Consume the $End line itself.
                self.next_line();
                return Ok(());
            }
            i = p + 1;
        }
    }
}
