//! The subset of XML that VTK files use, parsed by hand into a small tree.
//!
//! Handles an `<?xml …?>` declaration and other processing instructions, comments,
//! `<!DOCTYPE …>`, CDATA sections, attributes in any order with single or double quotes
//! and the five predefined entities plus character references, and whitespace anywhere the
//! grammar allows it. Element contents are kept as byte ranges into the input (arrays can be
//! large: nothing is copied). The content of `<AppendedData>` is raw bytes that may contain
//! anything, so it runs from the start tag to the *last* `</AppendedData>` of the file.
//! Never panics; nesting deeper than [`MAX_DEPTH`] is an error.

use std::ops::Range;

/// Deepest element nesting accepted (VTK files use 5 levels).
pub(crate) const MAX_DEPTH: usize = 64;

/// An element: name, attributes (values unescaped), children and its content's byte range.
#[derive(Debug, Clone)]
pub(crate) struct XmlElement<'a> {
    pub name: &'a str,
    pub attributes: Vec<(&'a str, String)>,
    pub children: Vec<XmlElement<'a>>,
    /// Bytes between the start and the end tag (empty for `<x/>`); for elements with
    /// children this includes them.
    pub content: Range<usize>,
    /// The character data directly inside the element: the pieces of `content` between
    /// child elements, comments and processing instructions (CDATA sections contribute
    /// their inside). VTK puts `<InformationKey>` children after an array's values.
    pub text: Vec<Range<usize>>,
    /// Byte offset of the start tag.
    pub offset: usize,
}

impl<'a> XmlElement<'a> {
    /// The value of attribute `name`, if present.
    pub fn attribute(&self, name: &str) -> Option<&str> {
        self.attributes
            .iter()
            .find(|(n, _)| *n == name)
            .map(|(_, v)| v.as_str())
    }

    /// The children named `name`.
    pub fn children_named<'s>(
        &'s self,
        name: &'s str,
    ) -> impl Iterator<Item = &'s XmlElement<'a>> + 's {
        self.children.iter().filter(move |c| c.name == name)
    }

    /// The element's character data (see [`XmlElement::text`]) from the document `b`.
    pub fn text_content<'b>(&self, b: &'b [u8]) -> std::borrow::Cow<'b, [u8]> {
        match self.text.as_slice() {
            [] => std::borrow::Cow::Borrowed(&[]),
            [one] => std::borrow::Cow::Borrowed(b.get(one.clone()).unwrap_or(&[])),
            many => std::borrow::Cow::Owned(
                many.iter()
                    .flat_map(|r| b.get(r.clone()).unwrap_or(&[]).iter().copied())
                    .collect(),
            ),
        }
    }

    /// The first child named `name`.
    pub fn child(&self, name: &str) -> Option<&XmlElement<'a>> {
        self.children.iter().find(|c| c.name == name)
    }
}

/// A syntax error at a byte offset.
#[derive(Debug)]
pub(crate) struct XmlError {
    pub offset: usize,
    pub message: String,
}

type R<T> = Result<T, XmlError>;

/// Parses a document and returns its root element.
pub(crate) fn parse_document(b: &[u8]) -> R<XmlElement<'_>> {
    let mut p = XmlParser { b, pos: 0 };
    if b.starts_with(&[0xef, 0xbb, 0xbf]) {
        p.pos = 3;
    }
    p.skip_misc()?;
    if p.peek() != Some(b'<') {
        return p.fail("expected an XML element such as <VTKFile>");
    }
    let root = p.element(0)?;
    p.skip_misc()?;
    if p.pos < b.len() {
        return p.fail("unexpected content after the root element");
    }
    Ok(root)
}

/// 1-based line number of a byte offset.
pub(crate) fn line_of(b: &[u8], offset: usize) -> usize {
    1 + b
        .get(..offset.min(b.len()))
        .unwrap_or(&[])
        .iter()
        .filter(|&&c| c == b'\n')
        .count()
}

struct XmlParser<'a> {
    b: &'a [u8],
    pos: usize,
}

fn is_name_char(c: u8) -> bool {
    c.is_ascii_alphanumeric() || matches!(c, b'_' | b':' | b'-' | b'.') || c >= 0x80
}

impl<'a> XmlParser<'a> {
    fn fail<T>(&self, message: impl Into<String>) -> R<T> {
        Err(XmlError {
            offset: self.pos,
            message: message.into(),
        })
    }

    fn peek(&self) -> Option<u8> {
        self.b.get(self.pos).copied()
    }

    fn rest(&self) -> &'a [u8] {
        self.b.get(self.pos..).unwrap_or(&[])
    }

    fn skip_ws(&mut self) {
        while self.peek().is_some_and(|c| c.is_ascii_whitespace()) {
            self.pos += 1;
        }
    }

    /// Advances past the next `pattern`, or fails with `what`.
    fn skip_past(&mut self, pattern: &[u8], what: &str) -> R<()> {
        match find(self.rest(), pattern) {
            Some(k) => {
                self.pos += k + pattern.len();
                Ok(())
            }
            None => self.fail(format!("unterminated {what} (no '{}')", show(pattern))),
        }
    }

    /// Whitespace, comments, processing instructions and DOCTYPE.
    fn skip_misc(&mut self) -> R<()> {
        loop {
            self.skip_ws();
            let rest = self.rest();
            if rest.starts_with(b"<?") {
                self.skip_past(b"?>", "processing instruction")?;
            } else if rest.starts_with(b"<!--") {
                self.skip_past(b"-->", "comment")?;
            } else if rest.starts_with(b"<!") {
                self.skip_past(b">", "declaration")?;
            } else {
                return Ok(());
            }
        }
    }

    fn name(&mut self) -> R<&'a str> {
        let start = self.pos;
        while self.peek().is_some_and(is_name_char) {
            self.pos += 1;
        }
        if self.pos == start {
            return self.fail("expected a name");
        }
        std::str::from_utf8(&self.b[start..self.pos]).or_else(|_| self.fail("a name is not UTF-8"))
    }

    /// An element starting at `<`.
    fn element(&mut self, depth: usize) -> R<XmlElement<'a>> {
        if depth >= MAX_DEPTH {
            return self.fail(format!("elements nested deeper than {MAX_DEPTH} levels"));
        }
        let offset = self.pos;
        self.pos += 1; // '<'
        let name = self.name()?;
        let mut attributes = Vec::new();
        loop {
            self.skip_ws();
            match self.peek() {
                Some(b'/') => {
                    if self.rest().starts_with(b"/>") {
                        self.pos += 2;
                        return Ok(XmlElement {
                            name,
                            attributes,
                            children: Vec::new(),
                            content: self.pos..self.pos,
                            text: Vec::new(),
                            offset,
                        });
                    }
                    return self.fail(format!("expected '/>' in the start tag of <{name}>"));
                }
                Some(b'>') => {
                    self.pos += 1;
                    break;
                }
                Some(_) => {
                    let attr = self.name()?;
                    self.skip_ws();
                    if self.peek() != Some(b'=') {
                        return self
                            .fail(format!("expected '=' after attribute {attr} of <{name}>"));
                    }
                    self.pos += 1;
                    self.skip_ws();
                    let Some(quote @ (b'"' | b'\'')) = self.peek() else {
                        return self.fail(format!(
                            "expected a quoted value for attribute {attr} of <{name}>"
                        ));
                    };
                    self.pos += 1;
                    let start = self.pos;
                    let Some(len) = self.rest().iter().position(|&c| c == quote) else {
                        return self.fail(format!(
                            "unterminated value of attribute {attr} of <{name}>"
                        ));
                    };
                    self.pos += len + 1;
                    let value =
                        unescape(&self.b[start..start + len]).map_err(|message| XmlError {
                            offset: start,
                            message: format!("attribute {attr} of <{name}>: {message}"),
                        })?;
                    if attributes.iter().any(|(a, _)| *a == attr) {
                        return self.fail(format!("attribute {attr} given twice in <{name}>"));
                    }
                    attributes.push((attr, value));
                }
                None => {
                    return self.fail(format!(
                        "unexpected end of file in the start tag of <{name}>"
                    ))
                }
            }
        }
        if name == "AppendedData" {
            // Raw bytes up to the last closing tag of the file.
            let start = self.pos;
            let close = b"</AppendedData";
            let Some(end) = rfind(self.rest(), close).map(|k| start + k) else {
                return self.fail("unexpected end of file: <AppendedData> has no </AppendedData>");
            };
            self.pos = end + close.len();
            self.skip_ws();
            if self.peek() != Some(b'>') {
                return self.fail("expected '>' after </AppendedData");
            }
            self.pos += 1;
            return Ok(XmlElement {
                name,
                attributes,
                children: Vec::new(),
                content: start..end,
                text: std::iter::once(start..end).collect(),
                offset,
            });
        }
        let start = self.pos;
        let mut children = Vec::new();
        let mut text = Vec::new();
        loop {
            let Some(k) = self.rest().iter().position(|&c| c == b'<') else {
                return self.fail(format!(
                    "unexpected end of file inside <{name}> (no </{name}>)"
                ));
            };
            if k > 0 {
                text.push(self.pos..self.pos + k);
            }
            self.pos += k;
            let rest = self.rest();
            if rest.starts_with(b"</") {
                let end = self.pos;
                self.pos += 2;
                let closing = self.name()?;
                if closing != name {
                    return self.fail(format!("</{closing}> closes <{name}>"));
                }
                self.skip_ws();
                if self.peek() != Some(b'>') {
                    return self.fail(format!("expected '>' after </{name}"));
                }
                self.pos += 1;
                return Ok(XmlElement {
                    name,
                    attributes,
                    children,
                    content: start..end,
                    text,
                    offset,
                });
            } else if rest.starts_with(b"<!--") {
                self.skip_past(b"-->", "comment")?;
            } else if rest.starts_with(b"<![CDATA[") {
                let inside = self.pos + 9;
                self.skip_past(b"]]>", "CDATA section")?;
                text.push(inside..self.pos - 3);
            } else if rest.starts_with(b"<?") {
                self.skip_past(b"?>", "processing instruction")?;
            } else {
                children.push(self.element(depth + 1)?);
            }
        }
    }
}

fn show(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// First position of `needle` in `hay`.
pub(crate) fn find(hay: &[u8], needle: &[u8]) -> Option<usize> {
    if needle.is_empty() || hay.len() < needle.len() {
        return None;
    }
    hay.windows(needle.len()).position(|w| w == needle)
}

/// Last position of `needle` in `hay`.
fn rfind(hay: &[u8], needle: &[u8]) -> Option<usize> {
    if needle.is_empty() || hay.len() < needle.len() {
        return None;
    }
    hay.windows(needle.len()).rposition(|w| w == needle)
}

/// Replaces entity and character references.
fn unescape(raw: &[u8]) -> Result<String, String> {
    let text = std::str::from_utf8(raw).map_err(|_| "not UTF-8".to_string())?;
    if !text.contains('&') {
        return Ok(text.to_string());
    }
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(k) = rest.find('&') {
        out.push_str(&rest[..k]);
        rest = &rest[k..];
        let Some(end) = rest.find(';') else {
            return Err(format!("unterminated reference {rest:?}"));
        };
        let entity = &rest[1..end];
        let ch = match entity {
            "amp" => '&',
            "lt" => '<',
            "gt" => '>',
            "quot" => '"',
            "apos" => '\'',
            _ => {
                let code =
                    if let Some(hex) = entity.strip_prefix("#x").or(entity.strip_prefix("#X")) {
                        u32::from_str_radix(hex, 16).ok()
                    } else if let Some(dec) = entity.strip_prefix('#') {
                        dec.parse().ok()
                    } else {
                        None
                    };
                code.and_then(char::from_u32)
                    .ok_or_else(|| format!("unknown reference &{entity};"))?
            }
        };
        out.push(ch);
        rest = &rest[end + 1..];
    }
    out.push_str(rest);
    Ok(out)
}

#[cfg(test)]
#[path = "tests/xml.rs"]
mod tests;
