//! The golden snapshot suite (`tests/snapshots.rs`, insta, committed files in
//! `tests/snapshots/`): run once per thread count, so that the curved meshes are shown not
//! to depend on the parallel schedule, or, with `--review`, re-recorded for review.

use std::process::Command;

use anyhow::Result;

use crate::{cargo, run};

/// The thread counts the suite must pass with.
const THREADS: [&str; 2] = ["1", "2"];

fn snapshot_test() -> Command {
    let mut cmd = cargo();
    // --workspace: the features of the test build, whose crates it reuses.
    cmd.args(["test", "--workspace", "--test", "snapshots"]);
    cmd.env_remove("HOCURVE_SNAPSHOT_QUICK");
    cmd
}

/// Runs the snapshot suite with `RAYON_NUM_THREADS` = 1 and 2.
pub fn snapshot_suite() -> Result<()> {
    for threads in THREADS {
        run(
            &format!("snapshot suite (RAYON_NUM_THREADS={threads})"),
            snapshot_test()
                .env("RAYON_NUM_THREADS", threads)
                .env("INSTA_UPDATE", "new"),
        )
        .map_err(|e| {
            anyhow::anyhow!(
                "{e}\n    a snapshot differs from the committed one (tests/snapshots/*.snap.new hold the new text).\n    If the change is intended: cargo xtask verify --review"
            )
        })?;
    }
    Ok(())
}

/// Re-records the snapshots: with `cargo-insta` installed, writes the new ones beside the
/// committed ones and opens `cargo insta review`; without, accepts them all
/// (`INSTA_UPDATE=always`) for review with `git diff tests/snapshots`.
pub fn review() -> Result<()> {
    let has_cargo_insta = cargo()
        .args(["insta", "--version"])
        .output()
        .is_ok_and(|o| o.status.success());
    if has_cargo_insta {
        // Failing snapshots leave .snap.new files; the review decides.
        let _ = run(
            "snapshot suite, recording changes",
            snapshot_test()
                .env("INSTA_UPDATE", "new")
                .env("INSTA_FORCE_PASS", "1"),
        );
        run("cargo insta review", cargo().args(["insta", "review"]))
    } else {
        run(
            "snapshot suite, accepting every change (INSTA_UPDATE=always)",
            snapshot_test().env("INSTA_UPDATE", "always"),
        )?;
        eprintln!(
            "cargo-insta is not installed (cargo install cargo-insta): every changed snapshot was accepted.\nReview the changes with `git diff --stat tests/snapshots` and `git diff tests/snapshots`; undo with `git checkout tests/snapshots`."
        );
        Ok(())
    }
}
