//! Every command in README.md and docs/*.md runs as written (issue 28 §3), at a reduced size,
//! so the docs cannot show a command the renderer refuses: the fenced `sh` blocks are read,
//! `\`-continued lines joined, comments dropped, and each line run by `sh` in one scratch folder
//! per document (in the document's order: a later command may read what an earlier one wrote),
//! with `caustic` on `PATH` and the repository's `scenes/`, `benches/` and `assets/` beside it.
//!
//! **Reduced, not rewritten.** Commands on the repository's scenes render at 192×192 with at
//! most 2 samples per pixel (none of these flags is added where a shard or sample range needs
//! the written count), 1–3 s instead of the written `--time`, and 2000 caustic / 1000 global
//! photons; the image files a command compares against (`test.exr`, `ref.exr`, …) are made
//! first with the same reduced settings, and `scene.ron` is a copy of `scenes/cornell.ron`.
//! `golden` commands keep their size and samples (already 64², 8 spp) and get the reduced photons. `sbatch` is a stand-in that
//! runs the job script locally (an array job for its first and last task, its `--time` budget
//! cut to 0.3 s), so the farm walkthrough runs end to end. Documents run in parallel threads.
//!
//! A line a document shows again verbatim runs at its first place only (the README shows the
//! `golden` pair twice; each is ~a fifth of the README's run).
//!
//! The few lines that cannot run here are listed in [`NOT_RUN`] with the reason; each entry
//! must still match a documented line, so the list cannot go stale.

use std::path::{Path, PathBuf};
use std::process::Command;

use crate::common;

/// Documented lines not run, by a substring of the line, with why.
const NOT_RUN: &[(&str, &str)] = &[
    ("cargo test --release", "the test command itself"),
    (
        "caustic preview",
        "a server until Ctrl-C: tests/it/preview.rs drives it in a browser",
    ),
    ("# preview of", "the output preview prints, not a command"),
    (
        "parallel -j4",
        "needs GNU parallel, which the machine lacks",
    ),
    (
        "JOB_COMPLETION_INDEX",
        "a Kubernetes indexed job's command, with paths inside its container",
    ),
    (
        "caustic converge SCENE --reference REF.exr",
        "the synopsis, with placeholders and optional [flags]",
    ),
];

/// A shell line of a fenced `sh` block.
#[derive(Debug)]
struct DocCommand {
    doc: PathBuf,
    line: usize,
    text: String,
}

fn doc_files() -> Vec<PathBuf> {
    let root = common::root();
    let mut docs = vec![root.join("README.md")];
    let mut more: Vec<PathBuf> = std::fs::read_dir(root.join("docs"))
        .expect("docs/")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    more.sort();
    docs.extend(more);
    docs
}

/// The commands of one document's `sh`/`bash`/`shell` blocks, continuations joined, trailing
/// `# comments` removed.
fn commands(doc: &Path) -> Vec<DocCommand> {
    let text = std::fs::read_to_string(doc).expect("read doc");
    let mut out = Vec::new();
    let mut in_block = false;
    let mut pending: Option<DocCommand> = None;
    for (i, line) in text.lines().enumerate() {
        let fence = line.trim_start().starts_with("```");
        if fence {
            let info = line.trim_start().trim_start_matches('`').trim();
            in_block = !in_block && matches!(info, "sh" | "bash" | "shell");
            continue;
        }
        if !in_block {
            continue;
        }
        let body = strip_comment(line);
        let (body, continued) = match body.trim_end().strip_suffix('\\') {
            Some(b) => (b.to_string(), true),
            None => (body.trim_end().to_string(), false),
        };
        let cmd = pending.get_or_insert_with(|| DocCommand {
            doc: doc.to_path_buf(),
            line: i + 1,
            text: String::new(),
        });
        if !cmd.text.is_empty() {
            cmd.text.push(' ');
        }
        cmd.text.push_str(body.trim());
        if !continued {
            if let Some(c) = pending.take()
                && !c.text.is_empty()
            {
                out.push(c);
            } else if line.trim_start().starts_with('#') {
                // A comment line of its own: keep it so NOT_RUN can name it.
                out.push(DocCommand {
                    doc: doc.to_path_buf(),
                    line: i + 1,
                    text: line.trim().to_string(),
                });
            }
        }
    }
    out
}

/// `line` without a trailing `# comment` (a `#` after whitespace, outside quotes).
fn strip_comment(line: &str) -> String {
    let (mut quote, mut prev_space) = (None, true);
    for (i, c) in line.char_indices() {
        match (quote, c) {
            (None, '\'' | '"') => quote = Some(c),
            (Some(q), _) if c == q => quote = None,
            (None, '#') if prev_space => return line[..i].to_string(),
            _ => {}
        }
        prev_space = c.is_whitespace();
    }
    line.to_string()
}

/// The flag values of `text` replaced by `f` where `f` returns one.
fn replace_flag(text: &str, flag: &str, f: impl Fn(&str) -> Option<String>) -> String {
    let words: Vec<&str> = text.split(' ').collect();
    let mut out: Vec<String> = Vec::with_capacity(words.len());
    let mut i = 0;
    while i < words.len() {
        out.push(words[i].to_string());
        if words[i] == flag
            && let Some(v) = words.get(i + 1)
        {
            out.push(f(v).unwrap_or_else(|| (*v).to_string()));
            i += 1;
        }
        i += 1;
    }
    out.join(" ")
}

const SIDE: &str = "192";
const PHOTON_FLAGS: &[(&str, &str)] = &[("--caustic-photons", "2000"), ("--photons", "1000")];

/// One `caustic …` invocation reduced: the size, samples, time and photons cut (see the module
/// doc); commands on a farm job's own scene are left alone (their settings hash must match the
/// plan's).
fn reduce_invocation(cmd: &str) -> String {
    let words: Vec<&str> = cmd.split_whitespace().collect();
    let sub = words.get(1).copied().unwrap_or("");
    let renders = matches!(sub, "render" | "converge" | "photons" | "golden" | "farm");
    // A farm job folder's scene (`job/scene.ron`, `local/scene.ron`): written by `farm plan`.
    let on_job = words.iter().any(|w| w.ends_with("/scene.ron"));
    if on_job && sub == "render" && !cmd.contains("--time") {
        // A shard of a time-budgeted plan has millions of samples per pixel and ends by its
        // job script's `--time`: give the rerun a budget (not a setting: the hash still holds).
        return format!("{cmd} --time 1s");
    }
    if !renders || on_job || (sub == "farm" && words.get(2) != Some(&"plan")) {
        return cmd.to_string();
    }
    if sub == "golden" {
        // The documented goldens are already small (64², 8 spp, as the project's own): size and
        // samples as written, so the check's false-alarm rate is the one docs/golden.md states;
        // only the photon counts are cut, in `update` and `check` alike (the photon scenes'
        // global maps were three quarters of this test's time).
        return with_photon_flags(cmd.to_string());
    }
    let mut c = cmd.to_string();
    for flag in ["--width", "--height"] {
        if c.contains(flag) {
            c = replace_flag(&c, flag, |_| Some(SIDE.into()));
        } else {
            c.push_str(&format!(" {flag} {SIDE}"));
        }
    }
    let keep_spp = c.contains("--shard") || c.contains("--samples") || sub == "farm";
    if !keep_spp {
        if c.contains("--spp") {
            c = replace_flag(&c, "--spp", |v| {
                Some(v.parse::<u32>().map_or(v.into(), |n| n.min(2).to_string()))
            });
        } else if sub != "converge" {
            c.push_str(" --spp 2");
        }
    }
    if sub != "farm" {
        let budget = if sub == "converge" { "3s" } else { "1s" };
        c = replace_flag(&c, "--time", |_| Some(budget.into()));
    }
    with_photon_flags(c)
}

/// `c` with the photon counts of [`PHOTON_FLAGS`] (replaced or added) and at most 2 final-gather
/// rays.
fn with_photon_flags(mut c: String) -> String {
    for (flag, value) in PHOTON_FLAGS {
        if c.contains(&format!("{flag} ")) {
            c = replace_flag(&c, flag, |_| Some((*value).into()));
        } else {
            c.push_str(&format!(" {flag} {value}"));
        }
    }
    replace_flag(&c, "--final-gather", |_| Some("2".into()))
}

/// The documented line as run: `cargo run --release --` is the built binary, and each
/// `caustic` invocation (of `&&` chains too) is reduced.
fn reduce(line: &str) -> String {
    let line = line.replace("cargo run --release -- ", "caustic ");
    if line.starts_with("scripts/error_vs_spp.sh ") {
        // Its sample counts are the third argument, a quoted list; the size as for render.
        let mut parts: Vec<&str> = line.splitn(3, '"').collect();
        if parts.len() == 3 {
            let rest = parts[2].split_once('"').map_or("", |(_, r)| r);
            parts = vec![parts[0], "1 2", rest];
            let mut l = format!("{}\"{}\"{}", parts[0], parts[1], parts[2]);
            for flag in ["--width", "--height"] {
                if l.contains(flag) {
                    l = replace_flag(&l, flag, |_| Some(SIDE.into()));
                } else {
                    l.push_str(&format!(" {flag} {SIDE}"));
                }
            }
            return l;
        }
    }
    line.split(" && ")
        .map(|part| {
            if part.trim_start().starts_with("caustic ") {
                reduce_invocation(part.trim())
            } else {
                part.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join(" && ")
}

/// The `sbatch` stand-in: runs the script with bash (an array job for its first and last task
/// ids only: the merge that follows is `--partial`), with the shards' `--time` budget cut
/// short; prints a job id as `--parsable` does.
const FAKE_SBATCH: &str = r#"#!/bin/sh
script=""
for a in "$@"; do script="$a"; done
tmp="$script.local"
sed 's/--time [0-9]*s/--time 0.3s/' "$script" > "$tmp"
range=$(sed -n 's/^#SBATCH --array=\([0-9]*\)-\([0-9]*\).*/\1 \2/p' "$script")
if [ -n "$range" ]; then
  set -- $range
  for i in $(printf '%s\n' "$1" "$2" | uniq); do
    SLURM_ARRAY_TASK_ID=$i bash "$tmp" >&2 || exit $?
  done
else
  SLURM_JOB_ID=1 bash "$tmp" >&2 || exit $?
fi
echo 1
"#;

/// A scratch folder with the repository's inputs beside it, `caustic` and the `sbatch`
/// stand-in on its `PATH`, and the reference images the docs compare against.
fn scratch(name: &str) -> PathBuf {
    let root = common::root();
    let dir = std::env::temp_dir().join(format!(
        "caustic-doc-commands-{}-{name}",
        std::process::id()
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("bin")).expect("scratch");
    std::fs::create_dir_all(dir.join("schema")).expect("scratch");
    std::fs::create_dir_all(dir.join("out")).expect("scratch");
    for sub in ["scenes", "benches", "assets", "scripts"] {
        std::os::unix::fs::symlink(root.join(sub), dir.join(sub)).expect("link");
    }
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_caustic"), dir.join("bin/caustic"))
        .expect("link caustic");
    let sbatch = dir.join("bin/sbatch");
    std::fs::write(&sbatch, FAKE_SBATCH).expect("sbatch");
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&sbatch, std::fs::Permissions::from_mode(0o755)).expect("chmod");
    std::fs::copy(root.join("scenes/cornell.ron"), dir.join("scene.ron")).expect("scene.ron");
    let reference = reduce_invocation("caustic render scenes/cornell.ron -o ref.exr --quiet");
    run(&dir, &reference).unwrap_or_else(|e| panic!("making ref.exr: {e}"));
    for copy in ["test.exr", "reference.exr", "golden.exr"] {
        std::fs::copy(dir.join("ref.exr"), dir.join(copy)).expect("copy reference");
    }
    dir
}

fn run(dir: &Path, line: &str) -> Result<(), String> {
    let path = format!(
        "{}:{}",
        dir.join("bin").display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let out = Command::new("sh")
        .args(["-ec", line])
        .current_dir(dir)
        .env("PATH", path)
        .env("CAUSTIC_BIN", env!("CARGO_BIN_EXE_caustic"))
        .output()
        .map_err(|e| format!("cannot start sh: {e}"))?;
    if out.status.success() {
        Ok(())
    } else {
        Err(format!(
            "exit {:?}\nstdout: {}\nstderr: {}",
            out.status.code(),
            String::from_utf8_lossy(&out.stdout),
            String::from_utf8_lossy(&out.stderr)
        ))
    }
}

#[test]
fn the_reduction_keeps_what_a_command_needs() {
    assert_eq!(
        reduce("caustic render scene.ron --spp 256 --shard 3/16 -o part3.part"),
        "caustic render scene.ron --spp 256 --shard 3/16 -o part3.part --width 192 --height 192 \
         --caustic-photons 2000 --photons 1000"
    );
    assert_eq!(
        reduce("caustic render scenes/water.ron --integrator path-ppm --photons 10000 --time 16s"),
        "caustic render scenes/water.ron --integrator path-ppm --photons 1000 --time 1s \
         --width 192 --height 192 --spp 2 --caustic-photons 2000"
    );
    assert_eq!(
        reduce("caustic merge job/shards/*.part -o final.exr"),
        "caustic merge job/shards/*.part -o final.exr"
    );
    assert_eq!(strip_comment("a '#x' b  # note"), "a '#x' b  ");
}

/// What running one doc's commands found: failures, which `NOT_RUN` entries matched, how many
/// commands ran.
struct DocRun {
    failures: Vec<String>,
    skipped: Vec<bool>,
    ran: usize,
}

/// Runs one doc's commands in order, in its own scratch folder.
fn run_doc(doc: &Path) -> DocRun {
    let mut out = DocRun {
        failures: Vec::new(),
        skipped: vec![false; NOT_RUN.len()],
        ran: 0,
    };
    let cmds = commands(doc);
    if cmds.is_empty() {
        return out;
    }
    let name = doc
        .file_stem()
        .and_then(|s| s.to_str())
        .unwrap_or("doc")
        .to_string();
    let dir = scratch(&name);
    let mut seen = std::collections::HashSet::new();
    for c in cmds {
        if let Some(k) = NOT_RUN.iter().position(|(s, _)| c.text.contains(s)) {
            out.skipped[k] = true;
            continue;
        }
        let line = reduce(&c.text);
        if !seen.insert(line.clone()) {
            // Shown again verbatim (README lists the golden pair in its command list and in
            // its own section): its first place ran it as written, in the same folder.
            continue;
        }
        out.ran += 1;
        let start = std::time::Instant::now();
        let result = run(&dir, &line);
        if std::env::var_os("DOC_COMMAND_TIMES").is_some() {
            // The cost of each documented command, to keep the suite's time in check.
            eprintln!(
                "{:7.2} s  {}:{}  {line}",
                start.elapsed().as_secs_f64(),
                c.doc.display(),
                c.line
            );
        }
        if let Err(e) = result {
            out.failures.push(format!(
                "{}:{}: `{}` (run as `{line}`): {e}",
                c.doc.display(),
                c.line,
                c.text
            ));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    out
}

#[test]
fn every_documented_command_runs_as_written() {
    // Each doc in its own thread and folder (its commands in order): much of the time is
    // process start-up and short time budgets, which overlap.
    let runs: Vec<DocRun> = std::thread::scope(|s| {
        let handles: Vec<_> = doc_files()
            .into_iter()
            .map(|doc| s.spawn(move || run_doc(&doc)))
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("a doc's runner panicked"))
            .collect()
    });
    let ran: usize = runs.iter().map(|r| r.ran).sum();
    let failures: Vec<&String> = runs.iter().flat_map(|r| &r.failures).collect();
    for (k, entry) in NOT_RUN.iter().enumerate() {
        assert!(
            runs.iter().any(|r| r.skipped[k]),
            "NOT_RUN entry `{}` matches no documented line",
            entry.0
        );
    }
    assert!(ran >= 30, "only {ran} documented commands found");
    assert!(
        failures.is_empty(),
        "{} documented commands fail:\n{}",
        failures.len(),
        failures
            .iter()
            .map(|f| f.as_str())
            .collect::<Vec<_>>()
            .join("\n\n")
    );
}
