use super::*;

#[test]
fn failure_leaves_no_file_and_keeps_the_old_one() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.txt");
    std::fs::write(&path, "old").unwrap();
    let r = write_atomically(&path, |w| {
        w.write_all(b"partial").unwrap();
        Err(IoError::Unsupported {
            path: path.clone(),
            message: "boom".into(),
        })
    });
    assert!(r.is_err());
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "old");
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    write_atomically(&path, |w| {
        w.write_all(b"new").map_err(|e| IoError::Os {
            path: path.clone(),
            source: e,
        })
    })
    .unwrap();
    assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
}

#[test]
fn an_interrupted_write_leaves_no_temporary_file() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("out.vtu");
    let r = write_atomically(&path, |w| {
        w.write_all(b"half a mesh").unwrap();
        w.flush().unwrap();
        // What the signal handler does mid-write (here only in this test's folder: other
        // tests write concurrently).
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
        remove_temporary_files_where(|f| f.starts_with(dir.path()));
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
        Err(IoError::Unsupported {
            path: path.clone(),
            message: "interrupted".into(),
        })
    });
    assert!(r.is_err());
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

#[test]
fn unwritable_folders_are_found_before_any_work() {
    let dir = tempfile::tempdir().unwrap();
    assert!(check_writable(&dir.path().join("out.vtu")).is_ok());
    let missing = dir.path().join("no/such/folder/out.vtu");
    let err = check_writable(&missing).unwrap_err().to_string();
    assert!(err.contains("no such folder"), "{err}");
    // The probe leaves nothing.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}
