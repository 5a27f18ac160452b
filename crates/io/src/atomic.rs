//! Writing output files so that a failure never leaves a truncated file behind.

use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::Mutex;

use crate::IoError;

/// The temporary files being written right now, so that a program interrupted by a signal
/// can remove them ([`remove_temporary_files`]) instead of leaving `.out.vtu.tmp<pid>`.
static IN_PROGRESS: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Removes every temporary file of a [`write_atomically`] still in progress; for a signal
/// handler that is about to end the program. The files they would have replaced are left
/// as they were.
pub fn remove_temporary_files() {
    remove_temporary_files_where(|_| true);
}

/// [`remove_temporary_files`] for the files `selected` picks.
fn remove_temporary_files_where(selected: impl Fn(&Path) -> bool) {
    let files = match IN_PROGRESS.lock() {
        Ok(list) => list.clone(),
        Err(poisoned) => poisoned.into_inner().clone(),
    };
    for file in files.iter().filter(|f| selected(f)) {
        let _ = std::fs::remove_file(file);
    }
}

fn register(tmp: &Path, add: bool) {
    let mut list = match IN_PROGRESS.lock() {
        Ok(list) => list,
        Err(poisoned) => poisoned.into_inner(),
    };
    if add {
        list.push(tmp.to_path_buf());
    } else {
        list.retain(|p| p != tmp);
    }
}

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
    register(&tmp, true);
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
    register(&tmp, false);
    result
}

/// Checks before any work that `path` can be written: its folder exists and a file can be
/// created in it (a probe, removed at once). The error names the folder and the reason.
pub fn check_writable(path: &Path) -> Result<(), IoError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let os = |source: std::io::Error| IoError::Os {
        path: dir.clone(),
        source,
    };
    if !dir.is_dir() {
        return Err(os(std::io::Error::new(
            std::io::ErrorKind::NotFound,
            "no such folder",
        )));
    }
    let probe = dir.join(format!(".hocurve-probe.tmp{}", std::process::id()));
    File::create(&probe).map_err(os)?;
    let _ = std::fs::remove_file(&probe);
    Ok(())
}

#[cfg(test)]
#[path = "tests/atomic.rs"]
mod tests;
