//! The bad-scene corpus: every `.ron`/`.toml` file in `tests/bad_scenes/` is an invalid scene that
//! `caustic check` must refuse with exit code 2 and a useful message (never a panic). The message
//! of each is snapshotted in `tests/it/snapshots/bad_scenes/`, and the file's first line (a comment
//! saying what is wrong and what the message must name) is stored with the snapshot, so a
//! reviewer sees the expectation next to the actual output.
//!
//! `caustic render` on a bad scene must exit 2 without creating or touching the output image.

use std::ffi::OsStr;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The corpus folder, relative to the crate root.
const CORPUS: &str = "tests/bad_scenes";

/// Where the snapshots live, relative to this file's folder.
const SNAPSHOTS: &str = "snapshots/bad_scenes";

/// Invalid scenes that `caustic check` currently ACCEPTS: known defects in src/, listed so the
/// test passes while the defect is open. Each must still be accepted; once one is refused, src/
/// was fixed: remove it from this list and accept its new snapshot.
const KNOWN_ACCEPTED: &[&str] = &[];

/// Files exempt from the "first line is a comment" rule (they could not contain one).
const NO_COMMENT: &[&str] = &["empty.ron"];

fn crate_root() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// Runs the built `caustic` with the crate root as working directory.
fn caustic<I, S>(args: I) -> Output
where
    I: IntoIterator<Item = S>,
    S: AsRef<OsStr>,
{
    Command::new(env!("CARGO_BIN_EXE_caustic"))
        .current_dir(crate_root())
        .args(args)
        .output()
        .expect("cannot run the caustic binary")
}

/// The corpus files, sorted, as paths relative to the crate root (`tests/bad_scenes/x.ron`).
fn corpus() -> Vec<PathBuf> {
    let dir = crate_root().join(CORPUS);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("cannot list {}: {e}", dir.display()))
        .map(|entry| entry.expect("cannot read a directory entry").path())
        .filter(|p| {
            p.is_file() && matches!(p.extension().and_then(OsStr::to_str), Some("ron" | "toml"))
        })
        .map(|p| Path::new(CORPUS).join(p.file_name().expect("file name")))
        .collect();
    files.sort();
    files
}

fn file_name(path: &Path) -> String {
    path.file_name()
        .expect("file name")
        .to_string_lossy()
        .into_owned()
}

/// The file's first line without its comment marker, which states what the message must say.
fn expectation(path: &Path) -> Option<String> {
    let bytes = std::fs::read(crate_root().join(path)).expect("cannot read corpus file");
    let first = bytes.split(|b| *b == b'\n').next().unwrap_or_default();
    let first = String::from_utf8_lossy(first);
    let marker = if path.extension() == Some(OsStr::new("ron")) {
        "//"
    } else {
        "#"
    };
    first
        .strip_prefix(marker)
        .map(|rest| rest.trim().to_string())
}

fn exit_code(out: &Output) -> Option<i32> {
    out.status.code()
}

/// Checks one corpus file; panics with a message naming it on any failure.
fn check_one(path: &Path) {
    let name = file_name(path);
    let description = expectation(path);
    assert!(
        description.is_some() || NO_COMMENT.contains(&name.as_str()),
        "{name}: the first line must be a comment saying what is wrong and what the message must name"
    );
    let out = caustic([OsStr::new("check"), path.as_os_str()]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    let stderr = String::from_utf8_lossy(&out.stderr);

    if KNOWN_ACCEPTED.contains(&name.as_str()) {
        assert!(
            exit_code(&out) == Some(0) && stdout.contains(": ok"),
            "{name} is listed in KNOWN_ACCEPTED but is no longer accepted (exit {:?}); \
             remove it from the list and accept its snapshot.\nstderr:\n{stderr}",
            exit_code(&out)
        );
        return;
    }

    assert!(
        !stderr.contains("panicked"),
        "{name}: caustic panicked:\n{stderr}"
    );
    assert_eq!(
        exit_code(&out),
        Some(2),
        "{name}: expected exit code 2 (bad input)\nstdout:\n{stdout}\nstderr:\n{stderr}"
    );
    assert!(
        !stderr.trim().is_empty(),
        "{name}: exit code 2 but nothing on stderr"
    );
    assert!(
        stdout.is_empty(),
        "{name}: a refused scene must print nothing on stdout, got:\n{stdout}"
    );

    let mut settings = insta::Settings::clone_current();
    settings.set_snapshot_path(SNAPSHOTS);
    settings.set_prepend_module_to_snapshot(false);
    settings.set_input_file(crate_root().join(path));
    settings.set_description(description.unwrap_or_else(|| "(empty file)".into()));
    settings.set_omit_expression(true);
    settings.bind(|| insta::assert_snapshot!(name.as_str(), stderr));
}

#[test]
fn every_bad_scene_is_refused_with_a_located_message() {
    let files = corpus();
    assert!(
        files.len() >= 40,
        "expected at least 40 bad scenes in {CORPUS}, found {}",
        files.len()
    );
    let names: Vec<String> = files.iter().map(|p| file_name(p)).collect();
    for known in KNOWN_ACCEPTED.iter().chain(NO_COMMENT) {
        assert!(
            names.iter().any(|n| n == known),
            "{known} is listed in this test but missing from {CORPUS}"
        );
    }

    // Check every file even when one fails, then name all that failed.
    let failed: Vec<&str> = files
        .iter()
        .zip(&names)
        .filter(|(path, _)| catch_unwind(AssertUnwindSafe(|| check_one(path))).is_err())
        .map(|(_, name)| name.as_str())
        .collect();
    assert!(
        failed.is_empty(),
        "{} of {} bad scenes failed (see the messages above): {}",
        failed.len(),
        files.len(),
        failed.join(", ")
    );
}

#[test]
fn no_stale_snapshots() {
    let dir = crate_root().join("tests").join(SNAPSHOTS);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return;
    };
    let names: Vec<String> = corpus().iter().map(|p| file_name(p)).collect();
    let stale: Vec<String> = entries
        .map(|e| {
            e.expect("directory entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|f| {
            f.strip_suffix(".snap").is_some_and(|scene| {
                !names.iter().any(|n| n == scene) || KNOWN_ACCEPTED.contains(&scene)
            })
        })
        .collect();
    assert!(
        stale.is_empty(),
        "snapshots without a (refused) corpus file in {}: {stale:?}",
        dir.display()
    );
}

/// A few bad scenes of different kinds: syntax, type, validation, asset and encoding errors.
const RENDER_CASES: &[&str] = &[
    "syntax_missing_comma.ron",
    "type_string_for_number.toml",
    "absurd_image_size.ron",
    "missing_obj.toml",
    "obj_out_of_range.ron",
    "not_utf8.toml",
    "deep_nesting.ron",
];

#[test]
fn render_of_a_bad_scene_writes_no_image() {
    for name in RENDER_CASES {
        let scene = Path::new(CORPUS).join(name);
        let dir = tempfile::tempdir().expect("temp dir");
        let output = dir.path().join("out.png");
        let out = caustic([
            OsStr::new("render"),
            scene.as_os_str(),
            OsStr::new("-o"),
            output.as_os_str(),
        ]);
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(
            exit_code(&out),
            Some(2),
            "{name}: render must exit 2\nstderr:\n{stderr}"
        );
        assert!(!stderr.contains("panicked"), "{name}: panicked:\n{stderr}");
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .expect("read temp dir")
            .map(|e| e.expect("entry").file_name())
            .collect();
        assert!(
            left.is_empty(),
            "{name}: render of a bad scene left files behind: {left:?}"
        );
    }
}

#[test]
fn render_of_a_bad_scene_leaves_an_existing_image_untouched() {
    // Not a valid PNG on purpose: any rewrite, truncation or re-encoding would change it.
    let original: Vec<u8> = b"\x89PNG\r\n\x1a\nkeep these exact bytes\x00\xff"
        .iter()
        .copied()
        .chain((0..=255).collect::<Vec<u8>>())
        .collect();
    for name in RENDER_CASES {
        let scene = Path::new(CORPUS).join(name);
        let dir = tempfile::tempdir().expect("temp dir");
        let output = dir.path().join("out.png");
        std::fs::write(&output, &original).expect("write out.png");
        let before = std::fs::metadata(&output)
            .and_then(|m| m.modified())
            .expect("mtime");
        let out = caustic([
            OsStr::new("render"),
            scene.as_os_str(),
            OsStr::new("-o"),
            output.as_os_str(),
        ]);
        assert_eq!(
            exit_code(&out),
            Some(2),
            "{name}: render must exit 2\nstderr:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let after = std::fs::read(&output).expect("out.png must still exist");
        assert!(
            after == original,
            "{name}: out.png was modified by a refused render"
        );
        let modified = std::fs::metadata(&output)
            .and_then(|m| m.modified())
            .expect("mtime");
        assert_eq!(before, modified, "{name}: out.png was rewritten");
        let entries = std::fs::read_dir(dir.path())
            .expect("read temp dir")
            .count();
        assert_eq!(
            entries, 1,
            "{name}: render left extra files next to out.png"
        );
    }
}

#[test]
fn render_of_a_bad_scene_with_default_output_writes_nothing() {
    // Without -o the image goes to `<stem>.png` in the working directory.
    let dir = tempfile::tempdir().expect("temp dir");
    for name in RENDER_CASES {
        let scene = crate_root().join(CORPUS).join(name);
        let out = Command::new(env!("CARGO_BIN_EXE_caustic"))
            .current_dir(dir.path())
            .arg("render")
            .arg(&scene)
            .output()
            .expect("cannot run the caustic binary");
        assert_eq!(
            exit_code(&out),
            Some(2),
            "{name}: render must exit 2\nstderr:\n{}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let left: Vec<_> = std::fs::read_dir(dir.path())
        .expect("read temp dir")
        .map(|e| e.expect("entry").file_name())
        .collect();
    assert!(left.is_empty(), "refused renders wrote {left:?}");
}

#[test]
fn a_scene_without_lights_only_warns() {
    // Not part of the corpus: it is valid, so `check` succeeds and the warning goes to stderr.
    let base = std::fs::read_to_string(crate_root().join(CORPUS).join("zero_radius.ron"))
        .expect("read zero_radius.ron");
    let text = base.replace("radius: 0)", "radius: 0.5)").replace(
        "lights: [Point(position: (0, 3, 2), power: (50, 50, 50))],",
        "lights: [],",
    );
    assert!(!text.contains("radius: 0)") && text.contains("lights: [],"));
    let dir = tempfile::tempdir().expect("temp dir");
    let scene = dir.path().join("no_lights.ron");
    std::fs::write(&scene, text).expect("write scene");
    let out = caustic([OsStr::new("check"), scene.as_os_str()]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(exit_code(&out), Some(0), "stderr:\n{stderr}");
    assert!(
        stderr.contains("warning: lights: the scene has no lights"),
        "stderr:\n{stderr}"
    );
    assert!(!stderr.contains("error"), "stderr:\n{stderr}");
}
