//! Farm rendering without a cluster: `render --shard`, `merge` and the job folder of `farm
//! plan`, whose batch scripts are run here by hand with a stand-in `sbatch`. The reference is
//! always a single-process render of the same samples, compared byte for byte. (The test
//! against a real Slurm is `scripts/slurm_test.sh`, run by `.ci/run`.)

use std::path::Path;
use std::process::Output;

use crate::common::caustic;

const CORNELL: &str = "scenes/cornell.ron";
/// A small path-traced Cornell box: indirect light, so every sample index matters.
const SMALL: [&str; 8] = [
    "--width",
    "24",
    "--height",
    "20",
    "--spp",
    "7",
    "--integrator",
    "path",
];

fn ok(out: &Output) -> String {
    assert!(
        out.status.success(),
        "status {:?}\nstdout: {}\nstderr: {}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn refused(out: &Output) -> String {
    assert_eq!(
        out.status.code(),
        Some(2),
        "expected exit 2; stdout: {}",
        String::from_utf8_lossy(&out.stdout)
    );
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn render(extra: &[&str], output: &Path) -> String {
    let o = output.to_str().expect("utf-8 path");
    // The raw estimate in PNGs too: `merge` writes it (a single render's PNG is denoised by
    // default).
    let mut args = vec![
        "render",
        CORNELL,
        "--threads",
        "2",
        "-q",
        "--no-denoise",
        "-o",
        o,
    ];
    args.extend_from_slice(&SMALL);
    args.extend_from_slice(extra);
    ok(&caustic(&args))
}

fn bytes(p: &Path) -> Vec<u8> {
    std::fs::read(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()))
}

fn s(p: &Path) -> &str {
    p.to_str().expect("utf-8 path")
}

/// Three shards (7 samples: 0..2, 2..4, 4..7), merged in a shuffled order, give the bytes of
/// one render, as EXR and PNG; the merged `.part` merges again to the same image.
#[test]
fn three_shards_merge_into_the_bytes_of_one_render() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    for ext in ["exr", "png"] {
        render(&[], &d.join(format!("single.{ext}")));
    }
    for i in 1..=3 {
        let out = render(
            &["--shard", &format!("{i}/3")],
            &d.join(format!("{i}.part")),
        );
        let spp = [2, 2, 3][i - 1];
        assert!(out.contains(&format!("{spp} spp")), "{out}");
    }
    let (p1, p2, p3) = (d.join("1.part"), d.join("2.part"), d.join("3.part"));
    let out = ok(&caustic(&[
        "merge",
        s(&p3),
        s(&p1),
        s(&p2),
        "-o",
        s(&d.join("m.exr")),
        "-o",
        s(&d.join("m.png")),
        "-o",
        s(&d.join("m.part")),
    ]));
    assert!(
        out.contains("merged 3 parts, 7 of 7 samples per pixel"),
        "{out}"
    );
    for ext in ["exr", "png"] {
        assert!(
            bytes(&d.join(format!("m.{ext}"))) == bytes(&d.join(format!("single.{ext}"))),
            "merged .{ext} differs from the single render"
        );
    }
    ok(&caustic(&[
        "merge",
        s(&d.join("m.part")),
        "-o",
        s(&d.join("again.exr")),
    ]));
    assert!(bytes(&d.join("again.exr")) == bytes(&d.join("single.exr")));
}

/// Mismatched settings, duplicates, overlaps and gaps are refused with the files named; with
/// `--partial` a gap is merged and equals a render of exactly the samples present.
#[test]
fn merge_refuses_mismatches_duplicates_overlaps_and_unasked_gaps() {
    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let part = |name: &str, extra: &[&str]| {
        let p = d.join(name);
        render(extra, &p);
        p
    };
    let a = part("a.part", &["--shard", "1/3"]);
    let c = part("c.part", &["--shard", "3/3"]);
    let seeded = part("seeded.part", &["--shard", "2/3", "--seed", "9"]);
    let wide = part("wide.part", &["--samples", "1..5"]);
    let out = d.join("out.exr");

    let e = refused(&caustic(&["merge", s(&a), s(&seeded), "-o", s(&out)]));
    assert!(
        e.contains("seeded.part")
            && e.contains("a.part")
            && e.contains("not parts of the same render"),
        "{e}"
    );
    let e = refused(&caustic(&["merge", s(&a), s(&c), s(&a), "-o", s(&out)]));
    assert!(e.contains("a.part` is given twice"), "{e}");
    let e = refused(&caustic(&["merge", s(&a), s(&wide), "-o", s(&out)]));
    assert!(
        e.contains("(samples 0..2) and") && e.contains("(samples 1..5) overlap"),
        "{e}"
    );
    let e = refused(&caustic(&["merge", s(&a), s(&c), "-o", s(&out)]));
    assert!(
        e.contains("samples 2..4 of the 7 per pixel are in none of the 2 parts")
            && e.contains("--partial"),
        "{e}"
    );
    assert!(!out.exists(), "a refused merge wrote its output");
    let e = refused(&caustic(&[
        "merge",
        s(&a),
        "--expect-hash",
        "0123456789abcdef",
        "-o",
        s(&out),
    ]));
    assert!(e.contains("not the expected 0123456789abcdef"), "{e}");

    // Partial: samples 0..2 and 4..7 merged; the reference renders the same two ranges as
    // parts of their own and merges those (a render of one range is `--samples`, checked too).
    let got = ok(&caustic(&[
        "merge",
        "--partial",
        s(&c),
        s(&a),
        "-o",
        s(&out),
    ]));
    assert!(
        got.contains("5 of 7 samples per pixel (partial: samples 2..4 missing)"),
        "{got}"
    );
    let r1 = part("r1.part", &["--samples", "0..2"]);
    let r2 = part("r2.part", &["--samples", "4..7"]);
    let reference = d.join("ref.exr");
    ok(&caustic(&[
        "merge",
        "--partial",
        s(&r1),
        s(&r2),
        "-o",
        s(&reference),
    ]));
    assert!(bytes(&out) == bytes(&reference));
    // One contiguous range: the merge equals a direct render of those samples to an image.
    let direct = d.join("direct.exr");
    render(&["--samples", "0..2"], &direct);
    let merged_a = d.join("a.exr");
    ok(&caustic(&["merge", "--partial", s(&a), "-o", s(&merged_a)]));
    assert!(bytes(&merged_a) == bytes(&direct));
}

#[test]
fn shard_flags_are_checked_before_rendering() {
    let e = refused(&caustic(&[
        "render", CORNELL, "--shard", "2/4", "-o", "x.png",
    ]));
    assert!(e.contains("must end in `.part`"), "{e}");
    let e = refused(&caustic(&[
        "render", CORNELL, "--shard", "5/4", "-o", "x.part",
    ]));
    assert!(e.contains("between 1 and N"), "{e}");
    let e = refused(&caustic(&[
        "render", CORNELL, "--spp", "3", "--shard", "1/4", "-o", "x.part",
    ]));
    assert!(e.contains("4 shards of 3 samples per pixel"), "{e}");
}

/// `farm plan` writes a job folder whose scripts, run by hand in order with a stand-in `sbatch`
/// (it records its arguments and prints job ids), render shards that merge into the bytes of a
/// single render; `farm status` follows along. The scene is photon-mapped, so the first job
/// really builds the photon cache and the shards read it.
#[cfg(unix)]
#[test]
fn a_planned_job_run_by_hand_equals_a_single_render() {
    use std::os::unix::fs::PermissionsExt;
    use std::process::Command;

    let dir = tempfile::tempdir().expect("tempdir");
    let d = dir.path();
    let job = d.join("job");
    let flags = [
        "--width",
        "24",
        "--height",
        "18",
        "--spp",
        "4",
        "--integrator",
        "photon",
        "--photons",
        "3000",
        "--caustic-photons",
        "3000",
        "--final-gather",
        "4",
    ];
    let mut args = vec!["farm", "plan", CORNELL, "--shards", "3", "--time", "90m"];
    args.extend_from_slice(&flags);
    args.extend_from_slice(&["--cpus", "2", "--partition", "gpu", "-o", s(&job)]);
    let out = ok(&caustic(&args));
    assert!(out.contains("3 shards of 24×18 at 4 spp (Photon)"), "{out}");
    let manifest = std::fs::read_to_string(job.join("manifest.json")).expect("manifest");
    assert!(
        manifest.contains("\"ranges\": [\n    [\n      0,\n      1\n    ],"),
        "{manifest}"
    );
    let shard_script = std::fs::read_to_string(job.join("shard.sbatch")).expect("script");
    for line in [
        "#SBATCH --array=1-3\n",
        "#SBATCH --time=1:30:00\n",
        "#SBATCH --cpus-per-task=2\n",
        "#SBATCH --partition=gpu\n",
        "#SBATCH --requeue\n",
        // 5400 s less a tenth and 30 s: the shard stops in time to write what it did.
        " --spp 4 --time 4830s ",
    ] {
        assert!(
            shard_script.contains(line),
            "{line} missing:\n{shard_script}"
        );
    }
    // Planning into the same folder again is refused.
    let e = refused(&caustic(&args));
    assert!(e.contains("already holds a farm job"), "{e}");

    let status = ok(&caustic(&["farm", "status", s(&job)]));
    assert!(
        status.contains("0 of 3 shards done: 0 of 4 samples per pixel"),
        "{status}"
    );
    assert!(status.contains("ETA: unknown"), "{status}");

    // A stand-in sbatch: logs its arguments, answers with a job id.
    let bin = d.join("bin");
    std::fs::create_dir(&bin).expect("mkdir");
    let log = d.join("sbatch.log");
    let fake = format!(
        "#!/bin/sh\necho \"$@\" >> '{}'\necho $(( $(wc -l < '{}') + 100 ))\n",
        log.display(),
        log.display()
    );
    std::fs::write(bin.join("sbatch"), fake).expect("write");
    std::fs::set_permissions(bin.join("sbatch"), std::fs::Permissions::from_mode(0o755))
        .expect("chmod");
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let run = |script: &str, env: &[(&str, &str)]| {
        let out = Command::new("bash")
            .arg(job.join(script))
            .envs(env.iter().copied())
            .env("PATH", &path)
            .env("SLURM_CPUS_PER_TASK", "2")
            .output()
            .expect("bash runs");
        ok(&out) + &String::from_utf8_lossy(&out.stderr)
    };
    let first = run("render.sbatch", &[("SLURM_JOB_ID", "7")]);
    assert!(
        first.contains("photon cache: miss: built and saved"),
        "{first}"
    );
    assert!(
        first.contains("shard array 101 and merge job 102 submitted"),
        "{first}"
    );
    let submitted = std::fs::read_to_string(&log).expect("sbatch log");
    let lines: Vec<&str> = submitted.lines().collect();
    assert_eq!(lines.len(), 2, "{submitted}");
    assert!(
        lines[0].starts_with("--parsable --dependency=afterany:7 ")
            && lines[0].ends_with("shard.sbatch")
    );
    assert!(
        lines[1].starts_with("--parsable --dependency=afterany:101 ")
            && lines[1].ends_with("merge.sbatch")
    );

    for i in ["1", "3"] {
        let out = run("shard.sbatch", &[("SLURM_ARRAY_TASK_ID", i)]);
        assert!(out.contains("photon cache: hit"), "{out}");
    }
    let status = ok(&caustic(&["farm", "status", s(&job)]));
    assert!(
        status.contains("2 of 3 shards done: 3 of 4 samples per pixel"),
        "{status}"
    );
    assert!(
        status.contains("shard 2/3: samples 1..2: not done"),
        "{status}"
    );
    assert!(
        status.contains("ETA: the 1 other shards need about"),
        "{status}"
    );
    run("shard.sbatch", &[("SLURM_ARRAY_TASK_ID", "2")]);
    let merged = run("merge.sbatch", &[]);
    assert!(
        merged.contains("merged 3 parts, 4 of 4 samples per pixel"),
        "{merged}"
    );
    let status = ok(&caustic(&["farm", "status", s(&job)]));
    assert!(
        status.contains("3 of 3 shards done: 4 of 4 samples per pixel"),
        "{status}"
    );

    for ext in ["exr", "png"] {
        let single = d.join(format!("single.{ext}"));
        let mut args = vec!["render", CORNELL, "-q", "--no-denoise", "-o", s(&single)];
        args.extend_from_slice(&flags);
        ok(&caustic(&args));
        assert!(
            bytes(&job.join(format!("cornell.{ext}"))) == bytes(&single),
            "the job's .{ext} differs from the single render"
        );
    }
}

/// A scene with assets (image textures, OBJ meshes) planned from another folder: the resolved
/// scene names them by absolute paths, and `plan` has checked that it renders with the same
/// settings hash as the original; a shard of it merges with a shard of the original.
#[test]
fn a_planned_scene_keeps_its_assets_and_its_hash() {
    let dir = tempfile::tempdir().expect("tempdir");
    let job = dir.path().join("job");
    let bath = crate::common::root().join("scenes/bath.ron");
    let small = ["--width", "16", "--height", "12", "--spp", "2"];
    let mut args = vec!["farm", "plan", s(&bath), "--shards", "2", "-o", s(&job)];
    args.extend_from_slice(&small);
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_caustic"))
        .args(&args)
        .current_dir(dir.path())
        .output()
        .expect("caustic runs");
    ok(&out);
    let scene = std::fs::read_to_string(job.join("scene.ron")).expect("scene.ron");
    let files: Vec<&str> = scene
        .lines()
        .filter_map(|l| l.trim().strip_prefix("file: \""))
        .collect();
    assert!(files.len() >= 3, "{scene}");
    for f in files {
        assert!(Path::new(f.trim_end_matches("\",")).is_absolute(), "{f}");
    }
    // Shard 1 of the planned scene and shard 2 of the original are parts of one render.
    let (p1, p2) = (dir.path().join("1.part"), dir.path().join("2.part"));
    let planned = job.join("scene.ron");
    let mut a = vec!["render", s(&planned), "--shard", "1/2", "-q", "-o", s(&p1)];
    a.extend_from_slice(&["--caustic-photons", "2000", "--photons", "2000"]);
    let mut b = vec!["render", s(&bath), "--shard", "2/2", "-q", "-o", s(&p2)];
    b.extend_from_slice(&small);
    b.extend_from_slice(&["--caustic-photons", "2000", "--photons", "2000"]);
    ok(&caustic(&a));
    ok(&caustic(&b));
    let merged = ok(&caustic(&[
        "merge",
        s(&p1),
        s(&p2),
        "-o",
        s(&dir.path().join("m.exr")),
    ]));
    assert!(merged.contains("2 of 2 samples per pixel"), "{merged}");
}

/// A scene that names no integrator gets the default estimator, whose per-pass photon counts
/// are chosen unless the command line states them: the planned scene pins the integrator and
/// the counts in effect, so its shards render what a render of the original with the same
/// flags renders (same settings hash, mergeable parts, same bytes).
#[test]
fn a_planned_default_estimator_scene_renders_like_the_original() {
    let dir = tempfile::tempdir().expect("tempdir");
    let cornell = crate::common::root().join(CORNELL);
    let small = ["--width", "24", "--height", "20", "--spp", "2"];
    for (name, photons) in [
        ("chosen", &[][..]),
        (
            "stated",
            &["--caustic-photons", "3000", "--photons", "500"][..],
        ),
    ] {
        let job = dir.path().join(name);
        let mut args = vec!["farm", "plan", s(&cornell), "--shards", "2", "-o", s(&job)];
        args.extend_from_slice(&small);
        args.extend_from_slice(photons);
        ok(&caustic(&args));
        let scene = std::fs::read_to_string(job.join("scene.ron")).expect("scene.ron");
        assert!(scene.contains("integrator: PathPpm"), "{scene}");
        let (planned, original) = (dir.path().join("p.exr"), dir.path().join("o.exr"));
        ok(&caustic(&[
            "render",
            s(&job.join("scene.ron")),
            "-q",
            "-o",
            s(&planned),
        ]));
        let mut b = vec![
            "render",
            s(&cornell),
            "-q",
            "--no-denoise",
            "-o",
            s(&original),
        ];
        b.extend_from_slice(&small);
        b.extend_from_slice(photons);
        ok(&caustic(&b));
        assert_eq!(bytes(&planned), bytes(&original), "{name}");
    }
}

/// Regression (issue #27): the resolved scene `farm plan` writes used to spell `Option` fields
/// as `Some(…)`, and `emission: Some((radiance: …))` did not parse again, so a scene with an
/// emissive shape could be planned but its shards refused it. Every scene in `scenes/` (the
/// emissive quad and cube of `lights.ron`, the bath's ceiling panel, …) survives plan →
/// re-parse: the planned file passes `caustic check`, and for `lights.ron` it describes the
/// same image (a small render of it has the bytes of one of the original).
#[test]
fn every_planned_scene_parses_again() {
    let dir = tempfile::tempdir().expect("tempdir");
    let small = ["--width", "12", "--height", "8", "--spp", "2"];
    for scene in crate::common::scene_files() {
        let name = scene.file_stem().and_then(|n| n.to_str()).expect("name");
        let ext = scene.extension().and_then(|e| e.to_str()).expect("ext");
        let job = dir.path().join(format!("{name}.{ext}"));
        let mut args = vec!["farm", "plan", s(&scene), "--shards", "2", "-o", s(&job)];
        args.extend_from_slice(&small);
        ok(&caustic(&args));
        let planned = job.join("scene.ron");
        let text = std::fs::read_to_string(&planned).expect("scene.ron");
        assert!(!text.contains("Some("), "{}: {text}", scene.display());
        ok(&caustic(&["check", s(&planned)]));
        if name == "lights" && ext == "ron" {
            let bare: String = text.split_whitespace().collect();
            assert!(bare.contains("emission:(radiance:"), "{text}");
            let (p, o) = (dir.path().join("p.png"), dir.path().join("o.png"));
            ok(&caustic(&["render", s(&planned), "-q", "-o", s(&p)]));
            let mut b = vec!["render", s(&scene), "-q", "-o", s(&o)];
            b.extend_from_slice(&small);
            ok(&caustic(&b));
            assert_eq!(
                bytes(&p),
                bytes(&o),
                "the planned lights scene renders differently"
            );
        }
    }
}
