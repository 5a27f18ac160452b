//! Writing output files so that a failure never leaves a truncated file behind.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::Path;

use crate::IoError;

/// Writes `path` through `fill`: the content goes to a temporary file in the same directory,
/// which is flushed, synced and renamed over `path` only when `fill` succeeded. On any error
/// the temporary file is removed and `path` is left as it was.
pub fn write_atomically<F>(path: &Path, fill: F) -> Result<(), IoError>
where
    F: FnOnce(&mut BufWriter<File>) -> Result<(), IoError>,
{
    let os = |source: std::io::Error| IoError::Os {
        path: path.to_path_buf(),
        source,
    };
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => std::path::PathBuf::from("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let tmp = dir.join(format!(".{name}.tmp{}", std::process::id()));
    let result = (|| {
        let file = File::create(&tmp).map_err(os)?;
        let mut writer = BufWriter::with_capacity(1 << 20, file);
        fill(&mut writer)?;
        writer.flush().map_err(os)?;
        let file = writer.into_inner().map_err(|e| os(e.into_error()))?;
        file.sync_all().map_err(os)?;
        std::fs::rename(&tmp, path).map_err(os)
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

#[cfg(test)]
#[path = "tests/atomic.rs"]
mod tests;
