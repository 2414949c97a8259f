//! What a golden check says, in words a reader understands without docs/golden.md: the
//! settings that changed since the golden was written (numbers printed as the scene file
//! wrote them), the verdict, the blocks that changed with how far beyond their noise, and the
//! golden's detection floor.

use serde_json::Value;

use super::batch_means::{BatchVerdict, BlockDiff};
use super::floor::DetectionFloor;
use super::noise_scaling::{MAX_REPLICATIONS, NoiseScaling};
use super::structure::{StructureSkip, StructureVerdict};

/// The scene's settings as sorted `(path, value)` pairs, from its serialized form: every field
/// after overrides, arrays of numbers kept whole (`materials.red.color = [0.7, 0.12, 0.1]`),
/// the seed left out (a check renders with another one on purpose).
#[must_use]
pub fn settings(scene: &Value) -> Vec<(String, String)> {
    let mut out = Vec::new();
    flatten(scene, String::new(), &mut out);
    out.retain(|(k, _)| k != "render.seed");
    out.sort();
    out
}

fn flatten(v: &Value, path: String, out: &mut Vec<(String, String)>) {
    match v {
        Value::Object(map) => {
            for (k, x) in map {
                let p = if path.is_empty() {
                    k.clone()
                } else {
                    format!("{path}.{k}")
                };
                flatten(x, p, out);
            }
        }
        Value::Array(items) if items.iter().any(|x| x.is_object() || x.is_array()) => {
            for (i, x) in items.iter().enumerate() {
                flatten(x, format!("{path}[{i}]"), out);
            }
        }
        leaf => out.push((path, text(leaf))),
    }
}

/// A value as the scene file would write it: a number that is an `f32` widened to `f64`
/// (`0.949999988079071`) is printed as the shortest decimal that reads back as that `f32`
/// (`0.95`), whole numbers without a fraction (`45`), other numbers by their shortest
/// round-trip form, arrays as `[a, b, c]`.
#[must_use]
pub fn text(v: &Value) -> String {
    match v {
        Value::Number(n) => match (n.as_i64(), n.as_u64(), n.as_f64()) {
            (Some(i), _, _) => i.to_string(),
            (_, Some(u), _) => u.to_string(),
            (_, _, Some(f)) => number(f),
            _ => n.to_string(),
        },
        Value::Array(items) => {
            let inner: Vec<String> = items.iter().map(text).collect();
            format!("[{}]", inner.join(", "))
        }
        other => other.to_string(),
    }
}

/// The shortest decimal of `f` that reads back as `f`, or as the `f32` it came from; whole
/// numbers below 10¹⁵ without a fraction.
#[must_use]
pub fn number(f: f64) -> String {
    let narrow = f as f32;
    if f.fract() == 0.0 && f.abs() < 1e15 {
        // Whole numbers as a scene writes them: `45`, not `45.0`.
        format!("{f}")
    } else if f64::from(narrow) == f {
        format!("{narrow:?}")
    } else {
        format!("{f:?}")
    }
}

/// The settings that differ: `path: golden → now` (or added/removed), sorted by path.
#[must_use]
pub fn settings_diff(golden: &[(String, String)], now: &[(String, String)]) -> Vec<String> {
    let find = |list: &[(String, String)], k: &str| {
        list.iter().find(|(p, _)| p == k).map(|(_, v)| v.clone())
    };
    let mut keys: Vec<&String> = golden.iter().chain(now).map(|(k, _)| k).collect();
    keys.sort();
    keys.dedup();
    keys.into_iter()
        .filter_map(|k| match (find(golden, k), find(now, k)) {
            (Some(a), Some(b)) if a != b => Some(format!("{k}: {a} → {b}")),
            (Some(a), None) => Some(format!("{k}: {a} → (none)")),
            (None, Some(b)) => Some(format!("{k}: (none) → {b}")),
            _ => None,
        })
        .collect()
}

/// A golden file written by an older caustic stored settings as `f64` text of `f32` values;
/// reads them again so that only real changes show.
fn normalize(value: &str) -> String {
    serde_json::from_str::<Value>(value).map_or_else(|_| value.to_string(), |v| text(&v))
}

/// [`settings_diff`] after re-printing both sides' numbers the same way.
#[must_use]
pub fn settings_diff_normalized(
    golden: &[(String, String)],
    now: &[(String, String)],
) -> Vec<String> {
    let n = |l: &[(String, String)]| -> Vec<(String, String)> {
        l.iter().map(|(k, v)| (k.clone(), normalize(v))).collect()
    };
    settings_diff(&n(golden), &n(now))
}

const CHANNELS: [&str; 3] = ["red", "green", "blue"];

/// "x 48–55, y 32–39 (8×8 px)" or "the whole image".
fn place(b: &BlockDiff, whole: bool) -> String {
    if whole {
        return format!("the whole image ({}×{} px)", b.width, b.height);
    }
    format!(
        "block x {}–{}, y {}–{} ({}×{} px)",
        b.x,
        b.x + b.width - 1,
        b.y,
        b.y + b.height - 1,
        b.width,
        b.height
    )
}

fn percent(golden: f64, now: f64) -> String {
    if golden == 0.0 {
        return if now == 0.0 {
            "0 %".into()
        } else {
            "from black".into()
        };
    }
    format!("{:+.1} %", 100.0 * (now - golden) / golden.abs())
}

fn rgb(c: [f64; 3]) -> String {
    format!("({:.4}, {:.4}, {:.4})", c[0], c[1], c[2])
}

/// One block in words: where, which channel moved how much, and how far beyond the noise.
#[must_use]
pub fn describe_block(v: &BatchVerdict, scale: usize, b: &BlockDiff) -> String {
    let s = &v.scales[scale];
    let c = b.worst_channel();
    let limit = s.t_limit(b.dof[c]);
    let how = if b.now[c] >= b.golden[c] {
        "brighter"
    } else {
        "darker"
    };
    let rel = if b.golden[c] != 0.0 {
        format!(
            "{} {:.1} % {how}",
            CHANNELS[c],
            100.0 * (b.now[c] - b.golden[c]).abs() / b.golden[c].abs()
        )
    } else {
        format!("{} {how} (the golden is black there)", CHANNELS[c])
    };
    let changes: Vec<String> = (0..3).map(|k| percent(b.golden[k], b.now[k])).collect();
    format!(
        "{}: {rel} than the golden (r g b {}; golden {} → now {}); the difference is {:.1} times its noise (σ {:.2e}), where {} {} of this size allow {:.1} times by chance",
        place(b, s.is_whole_image()),
        changes.join(" "),
        rgb(b.golden),
        rgb(b.now),
        b.t[c].abs(),
        b.se[c],
        s.blocks.len(),
        if s.blocks.len() == 1 {
            "block"
        } else {
            "blocks"
        },
        limit
    )
}

/// The verdict's one-line summary: the largest difference relative to what chance allows.
#[must_use]
pub fn summary(v: &BatchVerdict) -> String {
    let (g, t) = v.batches;
    let Some(&(scale, b)) = v.closest(1).first() else {
        return "no block to compare".into();
    };
    let s = &v.scales[scale];
    let c = b.worst_channel();
    format!(
        "largest difference {:.1} times its noise ({}, {}) where {:.1} is allowed; {g} and {t} batches, α {}",
        b.t[c].abs(),
        place(b, s.is_whole_image()),
        CHANNELS[c],
        s.t_limit(b.dof[c]),
        v.test.alpha
    )
}

/// The lines that explain a changed verdict: the changed blocks, the most significant first
/// (at most `listed`), and how many more there are.
#[must_use]
pub fn changed_lines(v: &BatchVerdict, listed: usize) -> Vec<String> {
    let changed = v.changed_blocks();
    let mut lines: Vec<String> = changed
        .iter()
        .take(listed)
        .map(|&(s, b)| format!("  {}", describe_block(v, s, b)))
        .collect();
    if changed.len() > listed {
        lines.push(format!(
            "  … and {} more blocks beyond their noise",
            changed.len() - listed
        ));
    }
    lines
}

/// The structure test's one-line summary for a verdict of "same": its p-value against its
/// limit, or why it did not run.
#[must_use]
pub fn structure_summary(s: &Result<StructureVerdict, StructureSkip>) -> String {
    match s {
        Ok(v) => format!(
            "pattern of light over small cells: p {} where below {} is a change ({} paired batches, {} sign flips)",
            number(v.p),
            number(v.alpha),
            v.batches,
            super::structure::FLIPS
        ),
        Err(e) => format!("pattern of light not tested: {e}"),
    }
}

/// The lines that explain a structure change: per cell size, the statistic against what
/// unchanged renders give, and the cells that moved most.
#[must_use]
pub fn structure_lines(v: &StructureVerdict) -> Vec<String> {
    let mut out = vec![format!(
        "  the pattern of light over small cells differs from the golden's: the sum of (difference / noise)² over the cells is beyond what {} sign flips of the {} paired batches give (p {} where below {} is a change):",
        super::structure::FLIPS,
        v.batches,
        number(v.p),
        number(v.alpha)
    )];
    for s in &v.scales {
        out.push(format!(
            "    over {0}×{0} px cells: {1:.0} for {2} cell-channels, where an unchanged scene gives {3:.0} (median) and exceeds {4:.0} with probability {5}",
            s.side,
            s.q,
            s.terms,
            s.null_median,
            s.null_limit,
            number(v.alpha)
        ));
    }
    if let Some(s) = v.scales.first() {
        let moves: Vec<String> = s
            .largest
            .iter()
            .map(|m| {
                format!(
                    "x {}–{}, y {}–{} {} {} ({:.1} times its noise)",
                    m.x,
                    m.x + m.width - 1,
                    m.y,
                    m.y + m.height - 1,
                    CHANNELS[m.channel],
                    percent(m.golden, m.now),
                    m.t.abs()
                )
            })
            .collect();
        if !moves.is_empty() {
            out.push(format!("    cells that moved most: {}", moves.join("; ")));
        }
    }
    out
}

/// The detection floor in words: "a change of every channel by ≥ 9.1 % in an 8×8 px block,
/// ≥ 4.0 % over 16×16 px, …, ≥ 0.8 % of the whole image is caught in 95 % of checks (median
/// block)".
#[must_use]
pub fn describe_floor(f: &DetectionFloor) -> String {
    let parts: Vec<String> = f
        .scales
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let pct = if s.median.is_finite() {
                format!("≥ {:.1} %", 100.0 * s.median)
            } else {
                "(black)".into()
            };
            if i + 1 == f.scales.len() {
                format!("{pct} of the whole image")
            } else {
                format!("{pct} over {0}×{0} px", s.side)
            }
        })
        .collect();
    let structure = if f.cell == 0 || !f.structure.is_finite() {
        String::new()
    } else if f.structure_active {
        format!(
            "; a change of the pattern of light that moves every {0}×{0} px cell by ±{1:.1} % (no change of the mean) is caught in 95 % of checks (approximately)",
            f.cell,
            100.0 * f.structure
        )
    } else {
        format!(
            "; the pattern of light over {0}×{0} px cells is not tested below {1} samples per pixel",
            f.cell,
            super::structure::MIN_BATCHES
        )
    };
    format!(
        "a change of {} is caught in 95 % of checks (of every channel; median block; {} batches){structure}{}",
        parts.join(", "),
        f.batches,
        describe_replications(f)
    )
}

/// For a `photon` golden: its batches are replications with maps of their own, at most
/// [`MAX_REPLICATIONS`]; empty for the others.
fn describe_replications(f: &DetectionFloor) -> String {
    match f.noise {
        NoiseScaling::Replications(_) => format!(
            "; {} replications, each with its own photon maps (at most {MAX_REPLICATIONS}: more samples per pixel are spread over them and lower only the camera samples' noise, more photons the maps')",
            f.batches
        ),
        NoiseScaling::Passes => String::new(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_flatten_to_paths_print_as_written_and_the_diff_names_what_changed() {
        let v: Value = serde_json::json!({
            "render": {"width": 64, "seed": 3},
            "lights": [{"Sphere": {"power": [45, 43, 39]}}],
            "materials": {"glass": {"ior": f64::from(1.33f32), "color": [f64::from(0.95f32), 0.5, 1e-7]}},
        });
        let out = settings(&v);
        assert_eq!(
            out,
            vec![
                (
                    "lights[0].Sphere.power".to_string(),
                    "[45, 43, 39]".to_string()
                ),
                ("materials.glass.color".into(), "[0.95, 0.5, 1e-7]".into()),
                ("materials.glass.ior".into(), "1.33".into()),
                ("render.width".into(), "64".into()),
            ]
        );
        assert_eq!(number(0.1), "0.1");
        assert_eq!(number(45.0), "45");
        assert_eq!(number(-2.0), "-2");
        assert_eq!(number(2.5e20), "2.5e20");
        assert_eq!(number(f64::from(0.1f32)), "0.1");
        assert_eq!(number(1.0 / 3.0), "0.3333333333333333");
        let mut now = out.clone();
        now[2].1 = "1.36".into();
        now.remove(3);
        now.push(("render.height".into(), "48".into()));
        assert_eq!(
            settings_diff(&out, &now),
            vec![
                "materials.glass.ior: 1.33 → 1.36".to_string(),
                "render.height: (none) → 48".into(),
                "render.width: 64 → (none)".into(),
            ]
        );
        // A golden of the first format printed f32 values widened.
        let old = vec![(
            "materials.glass.ior".to_string(),
            "1.3300000429153442".to_string(),
        )];
        let new = vec![("materials.glass.ior".to_string(), "1.33".to_string())];
        assert!(settings_diff_normalized(&old, &new).is_empty());
    }
}
