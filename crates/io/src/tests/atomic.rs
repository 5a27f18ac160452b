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

fn names(dir: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Staged outputs appear together at the commit, keep their extension while staged, and
/// replace older files.
#[test]
fn staged_outputs_appear_together_at_the_commit() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("out.vtu");
    let report = dir.path().join("report.json");
    std::fs::write(&report, "old report").unwrap();
    let mut staged = StagedOutputs::new();
    let tmp = staged.stage(&mesh);
    assert_eq!(tmp.extension().unwrap(), "vtu");
    assert!(tmp.to_string_lossy().contains(".tmp"));
    std::fs::write(&tmp, "mesh").unwrap();
    write_atomically(&staged.stage(&report), |w| {
        w.write_all(b"new report").map_err(|source| IoError::Os {
            path: report.clone(),
            source,
        })
    })
    .unwrap();
    let plots = dir.path().join("plots");
    staged.create_dir(&plots).unwrap();
    std::fs::write(staged.stage(&plots.join("a.svg")), "svg").unwrap();
    // Nothing in place yet.
    assert!(!mesh.exists());
    assert_eq!(std::fs::read_to_string(&report).unwrap(), "old report");
    staged.commit().unwrap();
    assert_eq!(std::fs::read_to_string(&mesh).unwrap(), "mesh");
    assert_eq!(std::fs::read_to_string(&report).unwrap(), "new report");
    assert_eq!(std::fs::read_to_string(plots.join("a.svg")).unwrap(), "svg");
    assert_eq!(names(dir.path()), ["out.vtu", "plots", "report.json"]);
    assert_eq!(names(&plots), ["a.svg"]);
}

/// A failure before the commit (dropped) or during it (a target that cannot be replaced)
/// leaves every target as it was: no new mesh beside an old report, no temporary file,
/// no folder created for the run.
#[test]
fn staged_outputs_are_all_or_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let mesh = dir.path().join("out.vtu");
    std::fs::write(&mesh, "old mesh").unwrap();
    {
        let mut staged = StagedOutputs::new();
        std::fs::write(staged.stage(&mesh), "new mesh").unwrap();
        staged.create_dir(&dir.path().join("plots")).unwrap();
        // Dropped: the report failed, say.
    }
    assert_eq!(names(dir.path()), ["out.vtu"]);
    assert_eq!(std::fs::read_to_string(&mesh).unwrap(), "old mesh");

    // The second target is a non-empty folder: its rename fails after the mesh's.
    let blocked = dir.path().join("report.json");
    std::fs::create_dir(&blocked).unwrap();
    std::fs::write(blocked.join("inside"), "x").unwrap();
    let mut staged = StagedOutputs::new();
    std::fs::write(staged.stage(&mesh), "new mesh").unwrap();
    std::fs::write(staged.stage(&blocked), "report").unwrap();
    let err = staged.commit().unwrap_err().to_string();
    assert!(err.contains("report.json"), "{err}");
    assert_eq!(std::fs::read_to_string(&mesh).unwrap(), "old mesh");
    assert_eq!(names(dir.path()), ["out.vtu", "report.json"]);

    // A rename failing after the mesh's (its staged file vanished): the mesh already
    // replaced gets its old content back, a target that did not exist goes again.
    let report = dir.path().join("report2.json");
    let mut staged = StagedOutputs::new();
    std::fs::write(staged.stage(&mesh), "new mesh").unwrap();
    std::fs::write(staged.stage(&dir.path().join("new.txt")), "new").unwrap();
    let vanished = staged.stage(&report);
    let err = staged.commit().unwrap_err().to_string();
    assert!(err.contains("report2.json"), "{err}");
    assert!(!vanished.exists());
    assert_eq!(std::fs::read_to_string(&mesh).unwrap(), "old mesh");
    assert_eq!(names(dir.path()), ["out.vtu", "report.json"]);
}

/// The signal handler's cleanup removes staged files and the folders created for them.
#[test]
fn staged_files_and_created_folders_are_removed_on_a_signal() {
    let dir = tempfile::tempdir().unwrap();
    let mut staged = StagedOutputs::new();
    let plots = dir.path().join("plots");
    staged.create_dir(&plots).unwrap();
    std::fs::write(staged.stage(&plots.join("a.svg")), "svg").unwrap();
    std::fs::write(staged.stage(&dir.path().join("out.vtu")), "mesh").unwrap();
    remove_temporary_files_where(|f| f.starts_with(dir.path()));
    assert!(names(dir.path()).is_empty(), "{:?}", names(dir.path()));
    drop(staged);
}

#[test]
fn a_folder_is_not_a_writable_file() {
    let dir = tempfile::tempdir().unwrap();
    let err = check_writable(dir.path()).unwrap_err().to_string();
    assert!(err.contains("is a folder"), "{err}");
}
