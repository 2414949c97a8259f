//! The bad-scene corpus: every `.ron`/`.toml` file in `tests/bad_scenes/` is an invalid scene that
//! `caustic check` must refuse with exit code 2 and a useful message (never a panic).
//!
//! Each file states what its message must say, and the test checks it: line 1 is a comment saying
//! what is wrong in words; the next lines are `expect:` headers, one per error the message must
//! report, in order:
//!
//! ```text
//! // expect: 11:51 | nodes[0].transform[0] | found `(1, 2)` | !did you mean
//! ```
//!
//! `LINE:COLUMN` is where the caret must be (`-` for a message that must have no location); each
//! `|`-separated text must appear in that error's block, and a text starting with `!` must not.
//! The whole message is also snapshotted in `tests/it/snapshots/bad_scenes/`, so a reviewer sees
//! the rendering next to the expectation.
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

/// What one error of a bad scene's message must say.
#[derive(Debug, Clone, PartialEq)]
struct Expect {
    /// Line and column of the caret, or `None` for an unlocated message.
    at: Option<(usize, usize)>,
    /// Texts the error must contain.
    contains: Vec<String>,
    /// Texts it must not contain.
    absent: Vec<String>,
}

/// The comment marker of a corpus file.
fn marker(path: &Path) -> &'static str {
    if path.extension() == Some(OsStr::new("ron")) {
        "//"
    } else {
        "#"
    }
}

/// The file's first line without its comment marker (what is wrong, in words), and its `expect:`
/// headers.
fn expectation(path: &Path) -> (Option<String>, Vec<Expect>) {
    let bytes = std::fs::read(crate_root().join(path)).expect("cannot read corpus file");
    let text = String::from_utf8_lossy(&bytes);
    let marker = marker(path);
    let mut lines = text.lines();
    let description = lines
        .next()
        .and_then(|l| l.strip_prefix(marker))
        .map(|rest| rest.trim().to_string());
    let expects = lines
        .map_while(|l| l.strip_prefix(marker)?.trim().strip_prefix("expect:"))
        .map(|e| {
            parse_expect(e)
                .unwrap_or_else(|m| panic!("{}: bad `expect:` header: {m}", path.display()))
        })
        .collect();
    (description, expects)
}

/// Parses `LINE:COLUMN | text | !absent text` (or `- | …`).
fn parse_expect(header: &str) -> Result<Expect, String> {
    let mut parts = header.split(" | ").map(str::trim);
    let at = parts.next().ok_or("empty header")?;
    let at = if at == "-" {
        None
    } else {
        let (line, col) = at
            .split_once(':')
            .ok_or(format!("`{at}` is not LINE:COLUMN or -"))?;
        let num = |s: &str| s.parse::<usize>().map_err(|e| format!("`{at}`: {e}"));
        Some((num(line)?, num(col)?))
    };
    let (mut contains, mut absent) = (Vec::new(), Vec::new());
    for part in parts {
        match part.strip_prefix('!') {
            Some(not) => absent.push(not.to_string()),
            None => contains.push(part.to_string()),
        }
    }
    if contains.is_empty() {
        return Err("no text the message must contain".into());
    }
    Ok(Expect {
        at,
        contains,
        absent,
    })
}

/// The error blocks of a message: each starts at an `error:` line and runs to the next
/// `error:`/`warning:` line or the closing count.
fn error_blocks(stderr: &str) -> Vec<String> {
    let mut blocks: Vec<(bool, String)> = Vec::new();
    for line in stderr.lines() {
        if line.starts_with("error:") || line.starts_with("warning:") {
            blocks.push((line.starts_with("error:"), String::new()));
        } else if line.ends_with(" found") && !line.starts_with(' ') {
            continue;
        }
        if let Some((_, block)) = blocks.last_mut() {
            block.push_str(line);
            block.push('\n');
        }
    }
    blocks
        .into_iter()
        .filter_map(|(is_error, b)| is_error.then_some(b))
        .collect()
}

/// Every way `stderr` (the message for corpus file `path`) falls short of `expects`.
fn unmet(path: &Path, expects: &[Expect], stderr: &str) -> Vec<String> {
    let blocks = error_blocks(stderr);
    let mut problems = Vec::new();
    if blocks.len() != expects.len() {
        problems.push(format!(
            "{} errors reported, {} expected",
            blocks.len(),
            expects.len()
        ));
    }
    let count = match blocks.len() {
        1 => "1 error found".to_string(),
        n => format!("{n} errors found"),
    };
    if !stderr.trim_end().ends_with(&count) {
        problems.push(format!("the message does not end with `{count}`"));
    }
    for (i, (expect, block)) in expects.iter().zip(&blocks).enumerate() {
        let at = block
            .lines()
            .find_map(|l| l.trim_start().strip_prefix("--> "))
            .map(str::to_string);
        let want = expect
            .at
            .map(|(line, col)| format!("{}:{line}:{col}", path.display()));
        if at != want {
            problems.push(format!(
                "error {}: located at {at:?}, expected {want:?}",
                i + 1
            ));
        }
        for text in &expect.contains {
            if !block.contains(text.as_str()) {
                problems.push(format!("error {}: does not say `{text}`", i + 1));
            }
        }
        for text in &expect.absent {
            if block.contains(text.as_str()) {
                problems.push(format!("error {}: says `{text}`, which it must not", i + 1));
            }
        }
    }
    problems
}

fn exit_code(out: &Output) -> Option<i32> {
    out.status.code()
}

/// Checks one corpus file; panics with a message naming it on any failure.
fn check_one(path: &Path) {
    let name = file_name(path);
    let (description, mut expects) = expectation(path);
    if NO_COMMENT.contains(&name.as_str()) {
        // An empty file cannot state its expectation: it is here.
        expects = vec![Expect {
            at: None,
            contains: vec![
                "is empty".into(),
                "`camera`, `materials` and `nodes`".into(),
            ],
            absent: Vec::new(),
        }];
    }
    assert!(
        description.is_some() || NO_COMMENT.contains(&name.as_str()),
        "{name}: the first line must be a comment saying what is wrong and what the message must name"
    );
    assert!(
        !expects.is_empty() || KNOWN_ACCEPTED.contains(&name.as_str()),
        "{name}: line 2 must be an `expect:` header (see the top of tests/it/bad_scenes.rs)"
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

    let problems = unmet(path, &expects, &stderr);
    assert!(
        problems.is_empty(),
        "{name}: the message does not meet the file's `expect:` headers:\n  {}\nstderr:\n{stderr}",
        problems.join("\n  ")
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
fn the_expectation_check_catches_a_wrong_place_text_or_count() {
    let path = Path::new("tests/bad_scenes/x.ron");
    let stderr = "error: camera.fov_y: must be within (0, 180) degrees, found 0\n \
                  --> tests/bad_scenes/x.ron:5:64\n  |\n5 | fov_y: 0\n  |        ^\n\n\
                  warning: lights: the scene has no lights\n\n1 error found\n";
    let good = parse_expect("5:64 | camera.fov_y | found 0 | !did you mean").unwrap();
    assert_eq!(
        unmet(path, std::slice::from_ref(&good), stderr),
        Vec::<String>::new()
    );
    for (header, problem) in [
        ("5:63 | camera.fov_y", "located at"),
        ("6:64 | camera.fov_y", "located at"),
        ("- | camera.fov_y", "located at"),
        ("5:64 | camera.eye", "does not say `camera.eye`"),
        ("5:64 | camera.fov_y | !found 0", "must not"),
    ] {
        let e = parse_expect(header).unwrap();
        let got = unmet(path, &[e], stderr);
        assert!(
            got.len() == 1 && got[0].contains(problem),
            "{header}: {got:?}"
        );
    }
    let got = unmet(path, &[good.clone(), good], stderr);
    assert!(
        got.iter()
            .any(|p| p.contains("1 errors reported, 2 expected")),
        "{got:?}"
    );
    assert!(parse_expect("5:64").is_err() && parse_expect("x | a").is_err());
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
