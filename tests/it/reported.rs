//! Inputs that users of other renderers reported as failures (issue 17 §3), each turned into a
//! test of the right result. The small inputs live in `tests/reported/<case>/`.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::root;

/// A folder of `tests/reported/`.
fn case(name: &str) -> PathBuf {
    root().join("tests/reported").join(name)
}

/// Runs `caustic` with `args` in `dir`, killing it (and failing) if it has not ended within
/// `limit`: returns (exit code, stdout, stderr).
fn run_within(dir: &Path, args: &[&str], limit: Duration) -> (i32, String, String) {
    let mut child = Command::new(env!("CARGO_BIN_EXE_caustic"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("caustic runs");
    let start = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if start.elapsed() > limit {
            child.kill().expect("kill");
            let _ = child.wait();
            panic!("`caustic {}` still running after {limit:?}", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("output");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

// ---- An output path that cannot be written -------------------------------------------------

/// Render flags that would take hours (512×512 at a million samples per pixel): a run that ends
/// in seconds refused the output before rendering.
const FOREVER: [&str; 6] = ["--width", "512", "--height", "512", "--spp", "1000000"];

fn refused_before_rendering(dir: &Path, output: &str, why: &str) {
    let scene = root().join("scenes/cornell.ron");
    let scene = scene.to_str().expect("utf-8 path");
    let mut args = vec!["render", scene, "-o", output];
    args.extend(FOREVER);
    let (code, stdout, stderr) = run_within(dir, &args, Duration::from_secs(60));
    assert_eq!(code, 2, "{stderr}");
    assert!(stdout.is_empty(), "nothing rendered: {stdout}");
    let first = stderr.lines().next().unwrap_or_default();
    assert!(
        first.starts_with(&format!("error: cannot write `{output}`")),
        "{stderr}"
    );
    assert!(first.contains(why), "{stderr}");
    assert!(
        !stderr.contains(".caustic-"),
        "no temporary file named: {stderr}"
    );
    let left: Vec<_> = std::fs::read_dir(dir)
        .expect("ls")
        .map(|e| e.expect("entry").file_name())
        .filter(|n| n.to_string_lossy().starts_with(".caustic-"))
        .collect();
    assert!(left.is_empty(), "probe files left: {left:?}");
}

#[test]
fn unwritable_outputs_are_refused_before_rendering_with_the_users_path() {
    let tmp = tempfile::tempdir().expect("tmp");
    let dir = tmp.path();
    std::fs::create_dir(dir.join("adir.png")).expect("mkdir");
    std::fs::write(dir.join("file.txt"), b"x").expect("write");
    refused_before_rendering(dir, "no_such_dir/out.png", "does not exist");
    refused_before_rendering(dir, "adir.png", "it is a folder");
    refused_before_rendering(dir, "file.txt/out.png", "is not a folder");
    // No permission: a folder without write permission refuses the probe, unless we run as a
    // user that permissions do not bind (root), which cannot be tested this way.
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        let locked = dir.join("locked");
        std::fs::create_dir(&locked).expect("mkdir");
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o555)).expect("chmod");
        let privileged = std::fs::write(locked.join("probe"), b"x").is_ok();
        if !privileged {
            refused_before_rendering(dir, "locked/out.png", "Permission denied");
        }
        std::fs::set_permissions(&locked, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    }
    // The checkpoint is checked the same way.
    let scene = root().join("scenes/cornell.ron");
    let mut args = vec![
        "render",
        scene.to_str().expect("utf-8"),
        "-o",
        "out.png",
        "--checkpoint",
        "gone/cp.png",
    ];
    args.extend(FOREVER);
    let (code, _, stderr) = run_within(dir, &args, Duration::from_secs(60));
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.starts_with("error: cannot write `gone/cp.png`: the folder `gone` does not exist"),
        "{stderr}"
    );
    assert!(!dir.join("out.png").exists());
}
