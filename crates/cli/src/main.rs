//! The `hocurve` command line.
fn main() {}
