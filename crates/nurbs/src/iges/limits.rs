//! The bounds that keep reading and converting any file finite: how deep references may
//! nest, and how often shared entities may be converted again.

/// Deepest chain of entity references accepted, and longest chain of 124 transformation
/// matrices (a trimmed surface of a surface of revolution of a composite of curves is 4
/// deep; real files stay far below this).
pub const MAX_NESTING: usize = 64;

/// Conversion visits an entity once per path of references that reaches it; it may visit
/// at most this many times the file's Parameter Data records (plus [`EXPANSION_MINIMUM`]).
/// Real files reference each entity from one or two parents.
pub const EXPANSION_FACTOR: usize = 64;

/// The expansion allowed whatever the file's size (small files may share a lot).
pub const EXPANSION_MINIMUM: usize = 100_000;
