//! The pass driver through the command line: `--time` budgets and `.part` films.

use crate::common;

#[test]
fn a_time_budget_renders_passes_until_it_is_spent() {
    let dir = tempfile::tempdir().expect("tempdir");
    let out = dir.path().join("t.png");
    let started = std::time::Instant::now();
    let run = common::caustic(&[
        "render",
        "scenes/cornell.ron",
        "--width",
        "24",
        "--height",
        "24",
        "--time",
        "1.5s",
        "--quiet",
        "-o",
        out.to_str().expect("utf-8 path"),
    ]);
    let took = started.elapsed().as_secs_f64();
    let stdout = String::from_utf8_lossy(&run.stdout);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    assert!(out.exists());
    // "t.png: 24×24, N spp, …": a 24×24 Cornell box takes far more than 16 spp in 1.5 s.
    let spp: u64 = stdout
        .split(", ")
        .find_map(|f| f.strip_suffix(" spp"))
        .and_then(|n| n.parse().ok())
        .unwrap_or_else(|| panic!("no spp in {stdout}"));
    assert!(spp >= 16, "{stdout}");
    assert!((1.4..6.0).contains(&took), "took {took} s");
}

#[test]
fn part_films_from_disjoint_runs_hold_their_samples() {
    let dir = tempfile::tempdir().expect("tempdir");
    let part = dir.path().join("a.part");
    let run = common::caustic(&[
        "render",
        "scenes/cornell.ron",
        "--width",
        "16",
        "--height",
        "12",
        "--spp",
        "3",
        "--quiet",
        "-o",
        part.to_str().expect("utf-8 path"),
    ]);
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let (sums, meta) = caustic::render::PixelSums::read(&part).expect("reads back");
    assert_eq!((sums.width, sums.height, sums.count(0)), (16, 12, 3));
    assert!(meta.contains("spp=3"), "{meta}");
    // The film's mean equals the PNG/EXR render of the same settings.
    let (film, _) = common::render_file(
        &common::root().join("scenes/cornell.ron"),
        &common::small(16, 12, 3),
        &Default::default(),
    );
    assert_eq!(sums.to_film().to_bytes(), film.to_bytes());
}
