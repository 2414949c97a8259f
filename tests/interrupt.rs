//! Stopping a render: passes over sample indices add up to the one-shot image bit for bit, and
//! the cancel flag stops a render without a film.

mod common;

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
    assert_eq!(job.samples_done(), 1);
    assert_eq!(job.snapshot().to_bytes(), after_one.to_bytes());
    assert!(matches!(job.finish(), Err(RenderError::Cancelled)));
}
