//! The `hocurve` binary as a user runs it: the demo with a report and plots, `quality` on
//! what it wrote, and the errors of bad requests (exit code 1, one line, no output file).

use std::path::Path;
use std::process::{Command, Output};

fn hocurve(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_hocurve"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("the hocurve binary runs")
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// What a run printed on stderr besides its progress lines (`hocurve: [   1.23 s] …`,
/// printed when stderr is not a terminal).
fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr)
        .lines()
        .filter(|l| !is_progress(l))
        .map(|l| format!("{l}\n"))
        .collect()
}

fn is_progress(line: &str) -> bool {
    line.starts_with("hocurve: [") && line.contains(" s] ")
}

/// A piped run logs one line per step with the elapsed time; `--quiet` prints nothing on
/// success; `-v` adds each step's duration, every CG iteration and the histograms.
#[test]
fn progress_is_logged_when_piped_and_quiet_is_silent() {
    let dir = tempfile::tempdir().unwrap();
    let args = ["demo", "sphere", "-p", "2", "-o", "s.vtu"];
    let out = hocurve(&args, dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let all = String::from_utf8_lossy(&out.stderr).into_owned();
    let progress: Vec<&str> = all.lines().filter(|l| is_progress(l)).collect();
    for step in [
        "placing high-order nodes",
        "placing boundary nodes on the geometry",
        "solving linear elasticity",
        "measuring quality",
        "writing the mesh",
        "finished",
    ] {
        assert_eq!(
            progress.iter().filter(|l| l.ends_with(step)).count(),
            1,
            "{step}: {all}"
        );
    }
    // Elapsed times never decrease.
    let times: Vec<f64> = progress
        .iter()
        .map(|l| {
            l["hocurve: [".len()..]
                .split(" s]")
                .next()
                .unwrap()
                .trim()
                .parse()
                .unwrap()
        })
        .collect();
    assert!(times.windows(2).all(|w| w[0] <= w[1]), "{all}");
    // The summary: at most 12 lines.
    let summary = stdout(&out);
    assert!(summary.lines().count() <= 12, "{summary}");
    assert!(
        summary.contains("validity") && summary.contains("time"),
        "{summary}"
    );

    let quiet = hocurve(&[&args[..], &["--quiet"]].concat(), dir.path());
    assert!(quiet.status.success());
    assert!(
        quiet.stdout.is_empty() && quiet.stderr.is_empty(),
        "{:?}",
        quiet
    );

    let verbose = hocurve(&[&args[..], &["-v"]].concat(), dir.path());
    assert!(verbose.status.success());
    let all = String::from_utf8_lossy(&verbose.stderr).into_owned();
    assert!(
        all.contains("CG iteration 1,") && all.contains("CG iteration 2,"),
        "{all}"
    );
    assert!(all.contains("solving linear elasticity done in"), "{all}");
    assert!(stdout(&verbose).contains("scaled Jacobian histogram"));

    // --quiet still reports errors, on one line.
    let failed = hocurve(
        &["demo", "sphere", "-p", "2", "-o", "s.stl", "-q"],
        dir.path(),
    );
    assert!(!failed.status.success());
    assert_eq!(String::from_utf8_lossy(&failed.stderr).lines().count(), 1);
}

#[test]
fn demo_writes_mesh_report_and_plots_and_quality_reads_the_mesh_back() {
    let dir = tempfile::tempdir().unwrap();
    let out = hocurve(
        &[
            "demo",
            "naca0012",
            "-p",
            "3",
            "-o",
            "naca.msh",
            "--report",
            "report.json",
            "--plots",
            "plots",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap())
            .unwrap();
    for field in [
        "order",
        "elements",
        "nodes",
        "dofs",
        "curved_facets",
        "max_geometry_distance",
        "solver",
        "residual",
        "min_scaled_jacobian",
        "invalid_elements",
        "fraction_above_0_95",
        "elements_below_0_5",
        "timings",
    ] {
        assert!(report.get(field).is_some(), "report lacks {field}");
    }
    assert_eq!(report["order"], 3);
    assert_eq!(report["invalid_elements"], 0);
    assert_eq!(report["certified_valid_elements"], report["elements"]);
    assert!(report["min_scaled_jacobian_lower_bound"].as_f64().unwrap() > 0.0);
    // CG stops on the residual, or earlier on a displacement error bound it reports.
    let residual = report["residual"].as_f64().unwrap();
    assert!(residual < 1e-8 || report["displacement_error_bound"].as_f64().is_some());
    assert!(residual < 1e-4);
    assert!(report["timings"]["solve"].as_f64().is_some());
    for plot in ["scaled_jacobian.svg", "stretching.svg"] {
        let svg = std::fs::read_to_string(dir.path().join("plots").join(plot)).unwrap();
        assert!(svg.starts_with("<svg") || svg.contains("<svg"), "{plot}");
    }
    // The written mesh carries the displacement and the quality as data.
    let msh = std::fs::read_to_string(dir.path().join("naca.msh")).unwrap();
    assert!(msh.contains("$NodeData") && msh.contains("\"displacement\""));
    assert!(msh.contains("$ElementData") && msh.contains("\"scaled_jacobian\""));

    // `quality` scores the file as `curve` scored the mesh.
    let q = hocurve(&["quality", "naca.msh", "--json"], dir.path());
    assert!(q.status.success(), "{}", stderr(&q));
    let summary: serde_json::Value = serde_json::from_str(&stdout(&q)).unwrap();
    let (a, b) = (
        summary["min_scaled_jacobian"].as_f64().unwrap(),
        report["min_scaled_jacobian"].as_f64().unwrap(),
    );
    assert!((a - b).abs() < 1e-10, "{a} vs {b}");
    assert_eq!(summary["elements"], report["elements"]);
}

#[test]
fn vtu_output_has_displacement_and_quality_arrays() {
    let dir = tempfile::tempdir().unwrap();
    let out = hocurve(
        &["demo", "naca0012", "-p", "2", "-o", "naca.vtu"],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let vtu = std::fs::read_to_string(dir.path().join("naca.vtu")).unwrap();
    for name in [
        "displacement",
        "scaled_jacobian",
        "stretching",
        "scaled_jacobian_lower_bound",
    ] {
        assert!(vtu.contains(&format!("Name=\"{name}\"")), "{name}");
    }
    let q = hocurve(&["quality", "naca.vtu"], dir.path());
    assert!(q.status.success(), "{}", stderr(&q));
    assert!(stdout(&q).contains("min scaled Jacobian"));
}

#[test]
fn bad_requests_fail_with_one_line_and_leave_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../fixtures");
    let mesh = fixtures.join("naca0012/naca0012.msh");
    let geometry = fixtures.join("naca0012/naca0012.json");
    let (mesh, geometry) = (mesh.to_str().unwrap(), geometry.to_str().unwrap());
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["curve", mesh, "-p", "3", "-o", "out.vtu"],
            "--geometry",
        ),
        (
            vec!["curve", mesh, "-p", "3", "-g", geometry, "-o", "out.stl"],
            "unknown output format",
        ),
        (
            vec![
                "curve", mesh, "-p", "3", "-g", geometry, "--slide", "symmetry", "-o", "out.vtu",
            ],
            "symmetry",
        ),
        (
            vec![
                "curve",
                "missing.msh",
                "-p",
                "3",
                "--straight",
                "-o",
                "out.vtu",
            ],
            "missing.msh",
        ),
        (vec!["quality", "missing.vtu"], "missing.vtu"),
    ];
    for (args, expected) in cases {
        let out = hocurve(&args, dir.path());
        assert_eq!(out.status.code(), Some(1), "{args:?}");
        let err = stderr(&out);
        assert!(err.starts_with("hocurve: error:"), "{args:?}: {err}");
        assert!(err.contains(expected), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    }
    let left: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(left.is_empty(), "files left behind: {left:?}");
}

/// An element that cannot be certified valid makes `curve` exit non-zero, name the element
/// by its Gmsh tag, and write nothing — unless `--allow-invalid`, which writes the mesh and
/// still exits non-zero. The thin layers on a very coarse sphere at p = 2 leave 117 elements
/// invalid after the elastic solve; the repair fixes them, so it is switched off here
/// (`--no-repair`), and the default run succeeds.
#[test]
fn uncertified_elements_fail_the_run_and_are_named() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mesh = root.join("fixtures/cad/sphere_layers_thin.msh");
    let geometry = root.join("fixtures/cad/sphere_layers_thin.json");
    let dir = tempfile::tempdir().unwrap();
    let args = |extra: &[&str]| -> Vec<String> {
        let mut a: Vec<String> = vec![
            "curve".into(),
            mesh.display().to_string(),
            "-p".into(),
            "2".into(),
            "--geometry".into(),
            geometry.display().to_string(),
            "-o".into(),
            "out.vtu".into(),
        ];
        a.extend(extra.iter().map(|s| s.to_string()));
        a
    };
    let run = |extra: &[&str]| {
        let a = args(extra);
        let refs: Vec<&str> = a.iter().map(String::as_str).collect();
        hocurve(&refs, dir.path())
    };
    // Uniform material: stiffened from the start (the default on layers) it is valid.
    let out = run(&["--no-repair", "--uniform-stiffness"]);
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("not certified valid"), "{err}");
    assert!(err.contains("element tag"), "{err}");
    assert!(err.contains("nothing written"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(!dir.path().join("out.vtu").exists());

    let out = run(&["--no-repair", "--uniform-stiffness", "--allow-invalid"]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("written anyway"), "{}", stderr(&out));
    assert!(dir.path().join("out.vtu").exists());
    std::fs::remove_file(dir.path().join("out.vtu")).unwrap();

    // With the repair (the default): every element certified, exit 0.
    let out = run(&[]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(dir.path().join("out.vtu").exists());
}

/// Outputs whose folder is missing are refused before any work, with one line naming the
/// folder once (not the OS text twice); nothing is written.
#[test]
fn missing_output_folders_fail_at_once_with_one_line() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mesh = root.join("fixtures/cad/sphere_coarse.msh");
    let geometry = root.join("fixtures/cad/sphere_coarse.json");
    let dir = tempfile::tempdir().unwrap();
    let (mesh, geometry) = (mesh.display().to_string(), geometry.display().to_string());
    let base = ["curve", &mesh, "-p", "2", "--geometry", &geometry];
    for extra in [
        vec!["-o", "missing/out.vtu"],
        vec!["-o", "out.vtu", "--report", "missing/report.json"],
        vec!["-o", "out.vtu", "--plots", "missing/plots"],
    ] {
        let args: Vec<&str> = base.iter().copied().chain(extra.iter().copied()).collect();
        let start = std::time::Instant::now();
        let out = hocurve(&args, dir.path());
        assert!(!out.status.success());
        let err = stderr(&out);
        assert_eq!(err.trim().lines().count(), 1, "{err}");
        assert!(err.contains("missing"), "{err}");
        assert_eq!(err.matches("no such folder").count(), 1, "{err}");
        assert!(stdout(&out).is_empty(), "work was done: {}", stdout(&out));
        assert!(start.elapsed().as_secs_f64() < 5.0);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
    }
    // A file that cannot be read: its OS error text appears once.
    let out = hocurve(
        &[
            "curve",
            "nothere.msh",
            "-p",
            "2",
            "--straight",
            "-o",
            "x.vtu",
        ],
        dir.path(),
    );
    let err = stderr(&out);
    assert_eq!(err.matches("No such file").count(), 1, "{err}");
}

/// SIGTERM at several moments of a run (curving, writing): the run either finished before
/// the signal, with all its outputs, or exits 130 leaving nothing, not even a temporary
/// file or the plots folder. Waits for the run to start (its header on stdout) and polls
/// for its end, so a slow or fast machine only shifts the moments hit.
#[cfg(unix)]
#[test]
fn a_terminated_run_leaves_no_file_behind() {
    use std::io::BufRead;
    use std::time::{Duration, Instant};
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut interrupted = 0;
    for delay_ms in [0, 400, 1200, 2500] {
        let dir = tempfile::tempdir().unwrap();
        let mut child = Command::new(env!("CARGO_BIN_EXE_hocurve"))
            .args(["curve"])
            .arg(root.join("fixtures/cad/sphere_occ.msh"))
            .args(["-p", "4", "--geometry"])
            .arg(root.join("fixtures/cad/sphere_occ.json"))
            .args([
                "-o",
                "out.vtu",
                "--report",
                "report.json",
                "--plots",
                "plots",
            ])
            .current_dir(dir.path())
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::null())
            .spawn()
            .expect("hocurve starts");
        // The header line comes once the mesh is read and curving begins; the rest of
        // stdout is drained so that the child never blocks on a full pipe.
        let stdout = child.stdout.take().expect("piped stdout");
        let (started_tx, started_rx) = std::sync::mpsc::channel();
        let drain = std::thread::spawn(move || {
            for line in std::io::BufReader::new(stdout).lines() {
                match line {
                    Ok(l) if l.contains("-> order") => {
                        let _ = started_tx.send(());
                    }
                    Ok(_) => {}
                    Err(_) => break,
                }
            }
        });
        let _ = started_rx.recv_timeout(Duration::from_secs(60));
        std::thread::sleep(Duration::from_millis(delay_ms));
        let finished_first = child.try_wait().expect("try_wait").is_some();
        if !finished_first {
            let killed = Command::new("kill")
                .args(["-TERM", &child.id().to_string()])
                .status()
                .expect("kill runs");
            assert!(killed.success());
        }
        let start = Instant::now();
        let status = loop {
            if let Some(status) = child.try_wait().expect("try_wait") {
                break status;
            }
            if start.elapsed() > Duration::from_secs(60) {
                let _ = child.kill();
                panic!("hocurve did not end within a minute of SIGTERM");
            }
            std::thread::sleep(Duration::from_millis(20));
        };
        let _ = drain.join();
        let mut left: Vec<String> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .collect();
        left.sort();
        if status.success() {
            // Finished before the signal: every output, no temporary file.
            assert_eq!(
                left,
                ["out.vtu", "plots", "report.json"],
                "after {delay_ms} ms"
            );
            let plots = std::fs::read_dir(dir.path().join("plots")).unwrap().count();
            assert_eq!(plots, 2);
        } else {
            interrupted += 1;
            assert_eq!(status.code(), Some(130), "after {delay_ms} ms");
            assert!(left.is_empty(), "after {delay_ms} ms: {left:?}");
        }
    }
    // At least the signal sent as curving began must have interrupted it.
    assert!(interrupted > 0, "every run finished before its signal");
}

/// A plot that cannot be written once the work is done (a folder stands where the file
/// goes) fails the run and leaves every output as it was: the older mesh is still there,
/// no report appears, nothing temporary is left.
#[test]
fn a_failed_plot_leaves_the_older_outputs_untouched() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("naca.vtu"), "older mesh").unwrap();
    let blocked = dir.path().join("plots/stretching.svg");
    std::fs::create_dir_all(&blocked).unwrap();
    std::fs::write(blocked.join("keep"), "x").unwrap();
    let out = hocurve(
        &[
            "demo",
            "naca0012",
            "-p",
            "2",
            "-o",
            "naca.vtu",
            "--report",
            "report.json",
            "--plots",
            "plots",
        ],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(err.contains("stretching.svg"), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert_eq!(
        std::fs::read_to_string(dir.path().join("naca.vtu")).unwrap(),
        "older mesh"
    );
    let mut left: Vec<String> = std::fs::read_dir(dir.path())
        .unwrap()
        .chain(std::fs::read_dir(dir.path().join("plots")).unwrap())
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    left.sort();
    assert_eq!(left, ["naca.vtu", "plots", "stretching.svg"]);
}

/// A node that no cell uses (a stray point in the file) is left out with a warning naming
/// its tag; the run succeeds (it used to end in a singular elastic system).
#[test]
fn nodes_of_no_cell_are_left_out_with_a_warning() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let text = std::fs::read_to_string(root.join("fixtures/formats/square_v22_ascii.msh"))
        .expect("the fixture");
    // One more node, tag 777, used by nothing.
    let start = text.find("$Nodes\n").expect("$Nodes") + "$Nodes\n".len();
    let count_end = start + text[start..].find('\n').expect("a count");
    let count: usize = text[start..count_end].trim().parse().expect("a count");
    let end = text.find("$EndNodes").expect("$EndNodes");
    let edited = format!(
        "{}{}{}777 5 5 0\n{}",
        &text[..start],
        count + 1,
        &text[count_end..end],
        &text[end..]
    );
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("stray.msh"), edited).unwrap();
    std::fs::write(
        dir.path().join("top.json"),
        r#"{"entities":[{"name":"top","kind":"nurbs_curve","degree":2,"knots":[0,0,0,1,1,1],"control_points":[[0,1],[0.5,1.1],[1,1]]}]}"#,
    )
    .unwrap();
    let out = hocurve(
        &[
            "curve",
            "stray.msh",
            "-p",
            "3",
            "--geometry",
            "top.json",
            "--geometry-tolerance",
            "0.1",
            "-o",
            "out.vtu",
            "--report",
            "report.json",
        ],
        dir.path(),
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let err = stderr(&out);
    assert!(err.contains("1 node(s) belong to no cell"), "{err}");
    assert!(err.contains("777"), "{err}");
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("report.json")).unwrap())
            .unwrap();
    assert_eq!(report["unused_node_tags"], serde_json::json!([777]));
    // The output holds the nodes of the mesh without the stray one, exactly.
    std::fs::write(dir.path().join("plain.msh"), &text).unwrap();
    let plain = hocurve(
        &[
            "curve",
            "plain.msh",
            "-p",
            "3",
            "--geometry",
            "top.json",
            "--geometry-tolerance",
            "0.1",
            "-o",
            "plain.vtu",
        ],
        dir.path(),
    );
    assert!(plain.status.success(), "{}", stderr(&plain));
    assert!(!stderr(&plain).contains("no cell"), "{}", stderr(&plain));
    let points = |name: &str| {
        let vtu = std::fs::read_to_string(dir.path().join(name)).unwrap();
        let at = vtu.find("NumberOfPoints=\"").expect("a piece") + "NumberOfPoints=\"".len();
        vtu[at..vtu[at..].find('"').unwrap() + at].to_string()
    };
    assert_eq!(points("out.vtu"), points("plain.vtu"));
}

/// An order the machine cannot hold is refused up front, with the estimate.
#[cfg(target_os = "linux")]
#[test]
fn an_order_beyond_the_machine_is_refused_with_its_estimate() {
    let dir = tempfile::tempdir().unwrap();
    let start = std::time::Instant::now();
    let out = hocurve(&["demo", "sphere", "-p", "20", "-o", "big.vtu"], dir.path());
    assert!(!out.status.success());
    let err = stderr(&out);
    assert!(err.contains("order 20 needs about"), "{err}");
    assert!(err.contains("GB"), "{err}");
    assert!(start.elapsed().as_secs_f64() < 20.0);
    assert!(!dir.path().join("big.vtu").exists());
}

/// `quality`'s histogram outputs are checked before the mesh is read: a missing folder is
/// reported, not the unreadable mesh.
#[test]
fn quality_checks_its_histogram_folders_first() {
    let dir = tempfile::tempdir().unwrap();
    let out = hocurve(
        &["quality", "nothere.msh", "--histogram", "missing/h.svg"],
        dir.path(),
    );
    assert_eq!(out.status.code(), Some(1));
    let err = stderr(&out);
    assert!(
        err.contains("missing") && err.contains("no such folder"),
        "{err}"
    );
    assert!(!err.contains("nothere.msh"), "{err}");
}

/// `--msh-version` and `--binary` choose the MSH flavour, `--compress` zlib-compresses a
/// `.vtu`; an option that does not apply to the output's format is refused before work.
#[test]
fn output_formats_are_chosen_by_options_and_misplaced_ones_refused() {
    let dir = tempfile::tempdir().unwrap();
    let base = ["demo", "naca0012", "-p", "2", "-q", "-o"];
    for (file, options, header) in [
        ("a.msh", &[][..], &b"$MeshFormat\n4.1 0 8\n"[..]),
        (
            "b.msh",
            &["--binary"][..],
            &b"$MeshFormat\n4.1 1 8\n\x01\0\0\0\n"[..],
        ),
        (
            "c.msh",
            &["--msh-version", "2.2"][..],
            &b"$MeshFormat\n2.2 0 8\n"[..],
        ),
        (
            "d.msh",
            &["--msh-version", "2.2", "--binary"][..],
            &b"$MeshFormat\n2.2 1 8\n\x01\0\0\0\n"[..],
        ),
    ] {
        let out = hocurve(&[&base[..], &[file], options].concat(), dir.path());
        assert!(out.status.success(), "{file}: {}", stderr(&out));
        let bytes = std::fs::read(dir.path().join(file)).unwrap();
        assert!(bytes.starts_with(header), "{file}");
        // Our reader takes every variant back.
        let q = hocurve(&["quality", file, "--json"], dir.path());
        assert!(q.status.success(), "{file}: {}", stderr(&q));
    }
    let out = hocurve(&[&base[..], &["z.vtu", "--compress"]].concat(), dir.path());
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(dir.path().join("z.vtu")).unwrap();
    assert!(text.contains("compressor=\"vtkZLibDataCompressor\""));
    for (file, option) in [("x.vtu", "--binary"), ("x.msh", "--compress")] {
        let out = hocurve(&[&base[..], &[file, option]].concat(), dir.path());
        assert!(!out.status.success());
        let err = stderr(&out);
        assert!(err.contains(" appl") && err.contains(" output ("), "{err}");
        assert!(!dir.path().join(file).exists());
    }
}

/// A STEP file that understates its faces' gap (sphere_on_block's fillet meets the sphere
/// to 2e-6; the file edited to state 1e-7) is refused with exit 1, nothing written, the
/// message naming the `--geometry-gap` that would do; given it, the run succeeds and its
/// report states that gap. A gap that is not a positive number is refused before any work.
#[test]
fn an_understated_gap_is_refused_naming_the_geometry_gap_that_would_do() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(root.join("fixtures/cad/sphere_on_block.step")).unwrap();
    let strict = text.replace("LENGTH_MEASURE(5.E-06)", "LENGTH_MEASURE(1.E-07)");
    assert_ne!(strict, text);
    std::fs::write(dir.path().join("strict.step"), strict).unwrap();
    let mesh = root
        .join("fixtures/cad/sphere_on_block.msh")
        .display()
        .to_string();
    let base = ["curve", &mesh, "-p", "2", "--geometry", "strict.step"];
    let with = |extra: &[&str]| {
        let args: Vec<&str> = base.iter().chain(extra).copied().collect();
        hocurve(&args, dir.path())
    };
    let refused = with(&["-o", "a.msh"]);
    assert_eq!(refused.status.code(), Some(1), "{}", stderr(&refused));
    let err = stderr(&refused);
    let gap = err
        .split("--geometry-gap ")
        .nth(1)
        .and_then(|rest| rest.split_whitespace().next())
        .unwrap_or_else(|| panic!("no gap named: {err}"))
        .to_string();
    assert!(!dir.path().join("a.msh").exists());
    let curved = with(&["-o", "b.msh", "--report", "b.json", "--geometry-gap", &gap]);
    assert!(curved.status.success(), "{}", stderr(&curved));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("b.json")).unwrap()).unwrap();
    let stated: f64 = gap.parse().unwrap();
    let uncertainty = report
        .pointer("/geometry_uncertainty")
        .and_then(|u| u.as_f64());
    assert_eq!(uncertainty, Some(stated), "{report}");
    for bad in ["0", "-1e-3", "nan"] {
        let out = with(&["-o", "c.msh", &format!("--geometry-gap={bad}")]);
        assert_eq!(out.status.code(), Some(1), "{bad}");
        assert!(
            stderr(&out).contains("--geometry-gap"),
            "{bad}: {}",
            stderr(&out)
        );
        assert!(!dir.path().join("c.msh").exists());
    }
}
