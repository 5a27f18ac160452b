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
