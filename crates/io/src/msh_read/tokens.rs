//! Tokens of ASCII MSH data: blanks, trimming, integers and reals as Gmsh writes them, and
//! tokens quoted for error messages.

/// Blank within a line.
pub(super) fn is_blank(c: u8) -> bool {
    matches!(c, b' ' | b'\t' | b'\r' | 0x0b | 0x0c)
}

/// `t` without leading and trailing blanks.
pub(super) fn trim(mut t: &[u8]) -> &[u8] {
    while let [first, rest @ ..] = t {
        if is_blank(*first) {
            t = rest;
        } else {
            break;
        }
    }
    while let [rest @ .., last] = t {
        if is_blank(*last) {
            t = rest;
        } else {
            break;
        }
    }
    t
}

/// A token or line quoted for a message (shortened, control characters escaped).
pub(super) fn show(t: &[u8]) -> String {
    const MAX: usize = 60;
    let s = String::from_utf8_lossy(&t[..t.len().min(MAX)]);
    let mut out = String::from("'");
    for c in s.chars() {
        if c.is_control() {
            out.extend(c.escape_default());
        } else {
            out.push(c);
        }
    }
    if t.len() > MAX {
        out.push_str("...");
    }
    out.push('\'');
    out
}

/// A signed decimal integer (optional sign, digits only), or `None`, also on overflow.
pub(super) fn parse_int(t: &[u8]) -> Option<i64> {
    let (neg, digits) = match t.split_first()? {
        (b'-', rest) => (true, rest),
        (b'+', rest) => (false, rest),
        _ => (false, t),
    };
    // The magnitude of i64::MIN, 2^63, fits in a u64.
    let magnitude = parse_digits(digits)?;
    if neg {
        0i64.checked_sub_unsigned(magnitude)
    } else {
        i64::try_from(magnitude).ok()
    }
}

/// An unsigned decimal integer (optional `+`, digits only), or `None`, also on overflow.
pub(super) fn parse_uint(t: &[u8]) -> Option<u64> {
    parse_digits(t.strip_prefix(b"+").unwrap_or(t))
}

/// One or more decimal digits and nothing else, or `None`, also on overflow.
fn parse_digits(digits: &[u8]) -> Option<u64> {
    if digits.is_empty() {
        return None;
    }
    let mut v: u64 = 0;
    for &c in digits {
        if !c.is_ascii_digit() {
            return None;
        }
        v = v.checked_mul(10)?.checked_add(u64::from(c - b'0'))?;
    }
    Some(v)
}

/// A real number as Rust's `f64` parser reads it.
pub(super) fn parse_float(t: &[u8]) -> Option<f64> {
    std::str::from_utf8(t).ok()?.parse().ok()
}
