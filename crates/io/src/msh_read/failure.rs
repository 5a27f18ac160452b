//! Parse failures of the MSH reader, before the file's path is attached: where, what, and
//! whether the input ended too early (which the section being read then rewrites with the
//! counts it announced).

use crate::error::Location;

/// A parse failure before the path is attached.
#[derive(Debug)]
pub(super) struct Fail {
    pub(super) location: Location,
    pub(super) message: String,
    /// The input ended too early (the section reader rewrites the message with its counts).
    pub(super) eof: bool,
}

impl Fail {
    /// A failure at `location` that is not the end of the input.
    pub(super) fn at(location: Location, message: impl Into<String>) -> Self {
        Fail {
            location,
            message: message.into(),
            eof: false,
        }
    }
}

pub(super) type R<T> = Result<T, Fail>;

pub(super) fn fail<T>(location: Location, message: impl Into<String>) -> R<T> {
    Err(Fail::at(location, message))
}

pub(super) fn eof_fail(message: impl Into<String>) -> Fail {
    Fail {
        location: Location::EndOfFile,
        message: message.into(),
        eof: true,
    }
}

/// The message for a section that holds `held` of the `announced` records (`noun`s) its
/// header announced.
pub(super) fn fewer_than_announced(noun: &str, section: &str, announced: u64, held: u64) -> String {
    format!("{noun} count in ${section} header is {announced} but the section holds {held}")
}

/// Rewrites an end-of-file failure inside a section with what the section announced.
pub(super) fn in_section(
    e: Fail,
    section: &str,
    what: &str,
    announced: Option<u64>,
    read: u64,
) -> Fail {
    if !e.eof {
        return e;
    }
    let detail = e
        .message
        .strip_prefix("unexpected end of file: ")
        .unwrap_or(&e.message)
        .to_string();
    let message = match announced {
        Some(n) if read < n => {
            format!("unexpected end of file in ${section} (expected {n} {what}, read {read})")
        }
        Some(n) => format!("unexpected end of file in ${section} (all {n} {what} read; {detail})"),
        None => format!("unexpected end of file in ${section} ({detail})"),
    };
    eof_fail(message)
}
