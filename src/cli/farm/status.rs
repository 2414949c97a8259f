//! `caustic farm status DIR`: which shards have a valid film (the job's hash, the shard's
//! samples), the samples per pixel done, and the time left estimated from the done shards.

use std::path::Path;

use caustic::Error;
use caustic::farm::part_meta::format_ranges;

use super::manifest::Manifest;

/// The state of one shard's film.
enum ShardState {
    /// Valid: its render time in seconds and the end of its samples (the shard's end, or
    /// less when its time budget stopped it early).
    Done(f64, u32),
    /// Not written yet (running, queued, failed or cancelled).
    Missing,
    /// Present but unusable: why.
    Invalid(String),
}

fn shard_state(m: &Manifest, hash: u64, dir: &Path, index: u32) -> ShardState {
    let path = Manifest::shard_path(dir, index);
    if !path.exists() {
        return ShardState::Missing;
    }
    let [start, end] = m.ranges[index as usize - 1];
    match caustic::farm::merge::read_part(&path) {
        // Worded as `caustic merge` would refuse it.
        Err(e) => ShardState::Invalid(super::super::merge::usage(e).to_string()),
        Ok((_, meta)) if meta.hash != hash => ShardState::Invalid(format!(
            "settings hash {:016x}, not the job's {}",
            meta.hash, m.hash
        )),
        Ok((_, meta)) => match meta.samples.as_slice() {
            [r] if r.start == start && r.end <= end => ShardState::Done(meta.seconds, r.end),
            other => ShardState::Invalid(format!(
                "holds samples {}, not the shard's {start}..{end}",
                format_ranges(other)
            )),
        },
    }
}

/// Prints each shard's state, the samples done and an estimate of the time left.
pub fn run(dir: &Path) -> Result<(), Error> {
    let m = Manifest::read(dir)?;
    let hash = m.hash_value()?;
    let (mut done, mut samples, mut seconds) = (0u32, 0u32, Vec::new());
    for index in 1..=m.shards {
        let [start, end] = m.ranges[index as usize - 1];
        let state = match shard_state(&m, hash, dir, index) {
            ShardState::Done(s, reached) => {
                done += 1;
                samples += reached - start;
                seconds.push(s);
                if reached == end {
                    format!("done in {s:.1} s")
                } else {
                    format!(
                        "stopped by its time budget after {s:.1} s with samples {start}..{reached} ({} of {})",
                        reached - start,
                        end - start
                    )
                }
            }
            ShardState::Missing => "not done (queued, running, failed or cancelled)".into(),
            ShardState::Invalid(why) => format!("INVALID: {why}"),
        };
        println!(
            "shard {index}/{}: samples {start}..{end}: {state}",
            m.shards
        );
    }
    println!(
        "{done} of {} shards done: {samples} of {} samples per pixel",
        m.shards, m.samples_per_pixel
    );
    let left = m.shards - done;
    if left > 0 && !seconds.is_empty() {
        let mean = seconds.iter().sum::<f64>() / seconds.len() as f64;
        println!(
            "ETA: the {left} other shards need about {:.0} s each ({:.0} s in all one after another; {:.0} s if they all run at once), from the done shards' mean",
            mean,
            mean * f64::from(left),
            mean
        );
    } else if left > 0 {
        println!("ETA: unknown until a shard is done");
    }
    for out in &m.outputs {
        let path = dir.join(out);
        if path.exists() {
            println!("merged image: {}", path.display());
        }
    }
    Ok(())
}
