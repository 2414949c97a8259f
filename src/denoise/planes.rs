//! Image planes (one float per pixel, row-major) and the box filter the patch distances and
//! error estimates are averaged with.

/// Box-filters rows `rows` of the `w`-wide plane `src` (holding rows `first..`) with radius
/// `r`, clamped at the image edges (each output is the mean of the in-image values), into
/// `out` (rows `rows`, row-major from `rows.start`). `h` is the image height: rows of the
/// window outside `first..first + src.len() / w` must not be needed (the caller gives
/// `first ≤ rows.start − r` or 0, and enough rows below). `scratch` holds one row.
/// Each sum is taken over its own window (no running sum: a huge value leaving the window
/// would take the small ones added after it with it).
#[allow(
    clippy::too_many_arguments,
    reason = "the plane, its first row, the image size, the radius, the rows, the scratch and the output: all needed, none belongs with another"
)]
pub fn box_rows(
    src: &[f32],
    first: usize,
    w: usize,
    h: usize,
    r: usize,
    rows: std::ops::Range<usize>,
    scratch: &mut Vec<f32>,
    out: &mut [f32],
) {
    let have = src.len() / w;
    scratch.clear();
    scratch.resize(w, 0.0);
    for y in rows.clone() {
        let top = y.saturating_sub(r).max(first);
        let bottom = (y + r).min(h - 1).min(first + have - 1);
        // Vertical sum into the scratch row.
        let v = &mut scratch[..w];
        v.fill(0.0);
        for yy in top..=bottom {
            for (o, s) in v
                .iter_mut()
                .zip(&src[(yy - first) * w..(yy - first + 1) * w])
            {
                *o += s;
            }
        }
        // Horizontal sum of shifted copies, then the mean.
        let o = &mut out[(y - rows.start) * w..(y - rows.start + 1) * w];
        o.copy_from_slice(v);
        for j in 1..=r.min(w - 1) {
            for (o, s) in o[j..].iter_mut().zip(&v[..w - j]) {
                *o += s;
            }
            for (o, s) in o[..w - j].iter_mut().zip(&v[j..]) {
                *o += s;
            }
        }
        let ny = (bottom + 1 - top) as f32;
        let full = 1.0 / ((2 * r + 1).min(w) as f32 * ny);
        // Full windows (r ≤ x < w − r) in one vectorisable loop, clamped ones at both ends.
        let (lo, hi) = (r.min(w), w.saturating_sub(r).max(r.min(w)));
        for o in &mut o[lo..hi] {
            *o *= full;
        }
        for x in (0..lo).chain(hi..w) {
            let nx = ((x + r).min(w - 1) + 1 - x.saturating_sub(r)) as f32;
            o[x] /= nx * ny;
        }
    }
}

/// The whole plane `src` (`w × h`) box-filtered with radius `r`.
#[must_use]
pub fn box_filter(src: &[f32], w: usize, h: usize, r: usize) -> Vec<f32> {
    let mut out = vec![0.0; src.len()];
    let mut scratch = Vec::new();
    box_rows(src, 0, w, h, r, 0..h, &mut scratch, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::box_filter;

    /// Against a direct sum over the clamped window, with full windows inside, windows wider
    /// than the image and a one-pixel-wide image.
    #[test]
    fn box_filter_is_the_mean_over_the_clamped_window() {
        for (w, h, r) in [(7, 5, 2), (3, 4, 2), (9, 2, 4), (8, 3, 4), (1, 3, 1)] {
            let src: Vec<f32> = (0..w * h).map(|i| ((i * 37) % 11) as f32).collect();
            let got = box_filter(&src, w, h, r);
            for y in 0..h {
                for x in 0..w {
                    let (mut s, mut n) = (0.0, 0.0);
                    for yy in y.saturating_sub(r)..=(y + r).min(h - 1) {
                        for xx in x.saturating_sub(r)..=(x + r).min(w - 1) {
                            s += src[yy * w + xx];
                            n += 1.0;
                        }
                    }
                    let want = s / n;
                    assert!(
                        (got[y * w + x] - want).abs() < 1e-5,
                        "{w}x{h} r {r} ({x}, {y})"
                    );
                }
            }
        }
    }
}
