//! A failure of the `.vtu` reader at a byte offset of the file, before the file's path
//! is attached.

use crate::xml::XmlElement;

/// A failure at a byte offset of the file (None: no particular place).
#[derive(Debug)]
pub(super) struct Fail {
    pub(super) offset: Option<usize>,
    pub(super) message: String,
}

pub(super) type R<T> = Result<T, Fail>;

pub(super) fn fail<T>(at: &XmlElement, message: impl Into<String>) -> R<T> {
    Err(Fail {
        offset: Some(at.offset),
        message: message.into(),
    })
}
