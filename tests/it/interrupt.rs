//! Stopping a render: passes over sample indices add up to the one-shot image bit for bit, the
//! cancel flag stops a render without a film, and Ctrl-C on `caustic render` writes nothing but
//! the last complete checkpoint.

use crate::common;

use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use caustic::pipeline::{SceneOverrides, prepare};
use caustic::render::{Region, RenderError, RenderJob, RenderOptions, render};
use caustic::render_scene::RenderScene;

fn cornell(overrides: &SceneOverrides) -> RenderScene {
    prepare(&common::root().join("scenes/cornell.ron"), overrides)
        .expect("cornell prepares")
        .render_scene
}

fn options(
    threads: usize,
    region: Option<Region>,
    cancel: Option<Arc<AtomicBool>>,
) -> RenderOptions {
    RenderOptions {
        threads: Some(threads),
        region,
        cancel,
        ..RenderOptions::default()
    }
}

#[test]
fn passes_add_up_to_the_one_shot_render_bit_for_bit() {
    // 40×36 has partial tiles on the right and bottom; 7 spp is not a square grid.
    let scene = cornell(&common::small(40, 36, 7));
    let crop = Region {
        x: 9,
        y: 5,
        width: 23,
        height: 20,
    };
    for threads in [1, 2] {
        for region in [None, Some(crop)] {
            let opts = options(threads, region, None);
            let whole = render(&scene, &opts).expect("one shot");
            let mut job = RenderJob::new(&scene, &opts).expect("job");
            for n in [1, 2, 4] {
                job.render_pass(n).expect("pass");
            }
            assert_eq!(job.samples_done(), 7);
            // The snapshot after the last sample is already the final image.
            assert_eq!(job.snapshot().to_bytes(), whole.film.to_bytes());
            let passes = job.finish().expect("nothing left to render");
            assert_eq!(
                passes.film.to_bytes(),
                whole.film.to_bytes(),
                "{threads} threads, region {region:?}"
            );
            assert_eq!(passes.stats.rays, whole.stats.rays);
            assert_eq!(passes.stats.samples, whole.stats.samples);
            assert_eq!(passes.stats.nan_samples, whole.stats.nan_samples);
        }
    }
    // Uneven passes, one asking for more than is left, and `finish` taking the remainder.
    let opts = options(2, None, None);
    let whole = render(&scene, &opts).expect("one shot");
    let mut job = RenderJob::new(&scene, &opts).expect("job");
    job.render_pass(3).expect("pass");
    job.render_pass(0).expect("an empty pass");
    assert_eq!(job.samples_done(), 3);
    let three = job.snapshot();
    assert_ne!(
        three.to_bytes(),
        whole.film.to_bytes(),
        "3 of 7 samples differ"
    );
    job.render_pass(100).expect("clamped pass");
    assert_eq!(job.samples_done(), 7);
    assert_eq!(
        job.finish().expect("done").film.to_bytes(),
        whole.film.to_bytes()
    );
    let mut job = RenderJob::new(&scene, &opts).expect("job");
    job.render_pass(5).expect("pass");
    assert_eq!(
        job.finish().expect("rest").film.to_bytes(),
        whole.film.to_bytes()
    );
}

/// A render that would take minutes on two cores.
fn long_scene() -> RenderScene {
    cornell(&common::small(256, 256, 4096))
}

#[test]
fn a_raised_cancel_flag_returns_cancelled_not_a_film() {
    let scene = long_scene();
    let flag = Arc::new(AtomicBool::new(true));
    let t = Instant::now();
    let result = render(&scene, &options(2, None, Some(flag)));
    assert!(matches!(result, Err(RenderError::Cancelled)), "{result:?}");
    assert!(t.elapsed() < Duration::from_secs(1), "{:?}", t.elapsed());
}

#[test]
fn cancelling_during_a_render_stops_it_promptly() {
    let scene = long_scene();
    let flag = Arc::new(AtomicBool::new(false));
    let raiser = {
        let flag = Arc::clone(&flag);
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(300));
            flag.store(true, Ordering::SeqCst);
            Instant::now()
        })
    };
    let result = render(&scene, &options(2, None, Some(flag)));
    let stopped = Instant::now();
    let raised = raiser.join().expect("raiser");
    assert!(matches!(result, Err(RenderError::Cancelled)), "{result:?}");
    let lag = stopped.saturating_duration_since(raised);
    assert!(
        lag < Duration::from_secs(1),
        "stopped {lag:?} after the flag"
    );
}

#[test]
fn a_cancelled_pass_leaves_the_last_complete_pass() {
    let scene = long_scene();
    let flag = Arc::new(AtomicBool::new(false));
    let mut job = RenderJob::new(&scene, &options(2, None, Some(Arc::clone(&flag)))).expect("job");
    job.render_pass(1).expect("first pass");
    let after_one = job.snapshot();
    assert!(
        after_one.mean().max_element() > 0.0,
        "the pass lit the film"
    );
    let raiser = {
        let flag = Arc::clone(&flag);
        std::thread::spawn(move || {
            std::thread::sleep(Duration::from_millis(200));
            flag.store(true, Ordering::SeqCst);
        })
    };
    // Several minutes of work, stopped part-way: its finished tiles must not leak in.
    let t = Instant::now();
    let result = job.render_pass(4000);
    raiser.join().expect("raiser");
    assert!(matches!(result, Err(RenderError::Cancelled)), "{result:?}");
    assert!(t.elapsed() < Duration::from_secs(2), "{:?}", t.elapsed());
    // The job holds whole sample indices only: a progressive integrator (the default on this
    // scene) may finish a pass or two of the 4000 before the flag rises, a single sweep none.
    // Whatever it kept must be exactly the image of that many complete samples.
    let kept = job.samples_done();
    assert!((1..4001).contains(&kept), "{kept}");
    let mut fresh = RenderJob::new(&scene, &options(2, None, None)).expect("job");
    fresh.render_pass(kept).expect("uncancelled passes");
    assert_eq!(job.snapshot().to_bytes(), fresh.snapshot().to_bytes());
    if kept == 1 {
        assert_eq!(job.snapshot().to_bytes(), after_one.to_bytes());
    }
    assert!(matches!(job.finish(), Err(RenderError::Cancelled)));
}

#[cfg(unix)]
mod cli {
    use std::path::Path;
    use std::process::{Child, Command, Output, Stdio};
    use std::time::{Duration, Instant};

    use super::common::root;

    const KEEP: &[u8] = b"an older image that Ctrl-C must not touch\n";

    fn spawn(args: &[&str]) -> Child {
        Command::new(env!("CARGO_BIN_EXE_caustic"))
            .args(args)
            .current_dir(root())
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .expect("caustic starts")
    }

    /// Sends SIGINT; returns the run's output and how long it took to exit after the signal.
    fn interrupt(mut child: Child) -> (Output, Duration) {
        let status = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status()
            .expect("kill runs");
        assert!(status.success(), "kill -INT failed");
        let sent = Instant::now();
        while child.try_wait().expect("wait").is_none() {
            if sent.elapsed() > Duration::from_secs(20) {
                let _ = child.kill();
                break;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        let lag = sent.elapsed();
        (child.wait_with_output().expect("output"), lag)
    }

    fn files_in(dir: &Path) -> Vec<String> {
        let mut v: Vec<String> = std::fs::read_dir(dir)
            .expect("dir")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        v.sort();
        v
    }

    fn render_args<'a>(out: &'a str, extra: &[&'a str]) -> Vec<&'a str> {
        let mut a = vec![
            "render",
            "scenes/cornell.ron",
            "-o",
            out,
            "--spp",
            "4096",
            "--threads",
            "2",
            "--quiet",
        ];
        a.extend_from_slice(extra);
        a
    }

    #[test]
    fn ctrl_c_stops_the_render_and_writes_nothing() {
        let dir = tempfile::tempdir().expect("tmp");
        let out = dir.path().join("out.png");
        std::fs::write(&out, KEEP).expect("seed the output");
        // With layer pictures beside the image: none of them is written either.
        let picture = dir.path().join("out.direct.png");
        std::fs::write(&picture, KEEP).expect("seed a layer picture");
        let child = spawn(&render_args(
            out.to_str().expect("utf8"),
            &[
                "--width",
                "1024",
                "--height",
                "1024",
                "--layers",
                "direct,caustic",
            ],
        ));
        std::thread::sleep(Duration::from_millis(1500));
        let (o, lag) = interrupt(child);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(130), "{stderr}");
        assert!(lag < Duration::from_secs(2), "exited {lag:?} after SIGINT");
        assert_eq!(stderr.trim(), "interrupted: no image written");
        assert!(
            o.stdout.is_empty(),
            "no summary: {}",
            String::from_utf8_lossy(&o.stdout)
        );
        assert_eq!(std::fs::read(&out).expect("output"), KEEP);
        assert_eq!(std::fs::read(&picture).expect("picture"), KEEP);
        assert_eq!(
            files_in(dir.path()),
            ["out.direct.png", "out.png"],
            "no temporary files left"
        );
    }

    #[test]
    fn ctrl_c_keeps_the_last_complete_checkpoint() {
        let dir = tempfile::tempdir().expect("tmp");
        let out = dir.path().join("out.png");
        let cp = dir.path().join("cp.png");
        std::fs::write(&out, KEEP).expect("seed the output");
        let child = spawn(&render_args(
            out.to_str().expect("utf8"),
            &[
                "--width",
                "640",
                "--height",
                "480",
                "--checkpoint",
                cp.to_str().expect("utf8"),
                "--checkpoint-every",
                "0",
            ],
        ));
        // The checkpoint appears (renamed into place, whole) after the first pass.
        let start = Instant::now();
        while !cp.exists() && start.elapsed() < Duration::from_secs(15) {
            std::thread::sleep(Duration::from_millis(20));
        }
        assert!(cp.exists(), "no checkpoint after {:?}", start.elapsed());
        std::thread::sleep(Duration::from_millis(300));
        let (o, lag) = interrupt(child);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(130), "{stderr}");
        assert!(lag < Duration::from_secs(2), "exited {lag:?} after SIGINT");
        assert_eq!(std::fs::read(&out).expect("output"), KEEP);
        let img = image::open(&cp).expect("the checkpoint is a readable PNG");
        assert_eq!((img.width(), img.height()), (640, 480));
        assert_eq!(
            files_in(dir.path()),
            ["cp.png", "out.png"],
            "no temporary files left"
        );
        let line = stderr.trim();
        assert!(
            line.starts_with("interrupted: no image written to `")
                && line.contains("cp.png` holds the last complete checkpoint (")
                && line.ends_with(" of 4096 samples per pixel)"),
            "{line}"
        );
        let n: u32 = line
            .rsplit_once('(')
            .and_then(|(_, rest)| rest.split(' ').next())
            .and_then(|n| n.parse().ok())
            .expect("a sample count");
        assert!((1..4096).contains(&n), "{line}");
        // Its content is exactly the first n samples of the 4096-spp render, as the library's
        // job gives them (not a one-shot n-spp render: pixel jitter is stratified over a grid
        // sized for all 4096 samples, so n of 4096 samples sit elsewhere than n of n).
        let scene = super::cornell(&super::common::small(640, 480, 4096));
        let mut job =
            caustic::render::RenderJob::new(&scene, &super::options(2, None, None)).expect("job");
        job.render_pass(n).expect("n samples");
        // Cornell states no exposure: the checkpoint's is automatic, its own snapshot's.
        let snapshot = job.snapshot();
        let (display, auto) = caustic::render::auto_exposure::resolve(
            &snapshot,
            None,
            caustic::render::auto_exposure::tonemap_for(None, None),
        );
        assert!(auto.is_some());
        let expected = caustic::render::output::to_srgb8(&snapshot, display);
        let stored = img.into_rgb8();
        let differing = stored
            .pixels()
            .zip(expected.pixels())
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(
            differing, 0,
            "{differing} pixels of the {n}-sample checkpoint differ from the first {n} samples"
        );
    }

    #[test]
    fn a_checkpointed_render_ends_with_the_same_image_and_removes_its_checkpoint() {
        let dir = tempfile::tempdir().expect("tmp");
        let plain = dir.path().join("plain.exr");
        let passes = dir.path().join("passes.exr");
        let cp = dir.path().join("cp.exr");
        // Replaced by the first checkpoint, so its absence at the end shows one was written.
        std::fs::write(&cp, KEEP).expect("seed the checkpoint");
        let base = [
            "render",
            "scenes/cornell.ron",
            "--width",
            "96",
            "--height",
            "64",
            "--spp",
            "40",
            "--threads",
            "2",
            "--quiet",
        ];
        let run = |extra: &[&str]| {
            let mut args = base.to_vec();
            args.extend_from_slice(extra);
            let o = super::common::caustic(&args);
            assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        };
        run(&["-o", plain.to_str().expect("utf8")]);
        run(&[
            "-o",
            passes.to_str().expect("utf8"),
            "--checkpoint",
            cp.to_str().expect("utf8"),
            "--checkpoint-every",
            "0",
        ]);
        assert_eq!(
            std::fs::read(&plain).expect("plain"),
            std::fs::read(&passes).expect("passes"),
            "checkpointing must not change a bit of the final image"
        );
        assert_eq!(files_in(dir.path()), ["passes.exr", "plain.exr"]);
    }

    #[test]
    fn checkpoint_flags_are_checked() {
        let bad = |args: &[&str], needle: &str| {
            let o = super::common::caustic(args);
            let stderr = String::from_utf8_lossy(&o.stderr);
            assert_eq!(o.status.code(), Some(2), "{args:?}: {stderr}");
            assert!(stderr.contains(needle), "{args:?}: {stderr}");
        };
        let r = ["render", "scenes/cornell.ron", "-o", "/nonexistent/x.png"];
        bad(
            &[&r[..], &["--checkpoint-every", "5"]].concat(),
            "--checkpoint <FILE>",
        );
        bad(
            &[&r[..], &["--checkpoint", "/nonexistent/x.png"]].concat(),
            "is the output file",
        );
        bad(&[&r[..], &["--checkpoint", "cp.jpg"]].concat(), "cp.jpg");
        bad(
            &[
                &r[..],
                &["--checkpoint", "cp.png", "--checkpoint-every", "soon"],
            ]
            .concat(),
            "seconds",
        );
    }
}

#[test]
fn checkpoint_intervals_take_units() {
    let dir = tempfile::tempdir().expect("temp dir");
    let (cp, out) = (dir.path().join("cp.png"), dir.path().join("x.png"));
    let o = crate::common::caustic(&[
        "render",
        "scenes/cornell.ron",
        "--width",
        "8",
        "--height",
        "8",
        "--spp",
        "2",
        "--checkpoint",
        cp.to_str().expect("utf-8"),
        "--checkpoint-every",
        "5m",
        "-o",
        out.to_str().expect("utf-8"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(out.exists());
}
