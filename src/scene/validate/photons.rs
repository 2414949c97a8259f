//! Checks of the `photons` block and of the photon budgets it implies.

use super::*;

impl<'a> Validator<'a> {
    /// A photon count: at most [`MAX_PHOTONS`] (the map's memory is stated in the message).
    pub(super) fn photon_count(&mut self, path: &str, n: u32) {
        if n > MAX_PHOTONS {
            self.out.push(
                Diagnostic::error(
                    path,
                    format!(
                        "must be at most {MAX_PHOTONS} photons, found {n} (a map that size could need {:.1} GB)",
                        f64::from(n) * 24.0 * 4.0 / 1e9
                    ),
                )
                .with_help("photon maps store up to a few photons per emitted photon at 24 bytes each; use `--time` or `ppm` passes for more"),
            );
        }
    }

    /// The caustic map's total (every light's own `caustic_photons`, plus `photons.caustic` when
    /// a light shares it) is bounded as each field is: refused up front, not capped, so no
    /// light's share changes silently (issue 29: three lights at 4e7 failed to allocate).
    pub(super) fn caustic_map_total(&mut self, scene: &SceneFile) {
        let own: Vec<(usize, u32)> = (scene.lights.iter().enumerate())
            .filter_map(|(i, l)| l.caustic_photons().map(|n| (i, n)))
            .collect();
        let mut parts: Vec<(String, u32)> = (own.iter())
            .map(|&(i, n)| (format!("lights[{i}].caustic_photons"), n))
            .collect();
        if own.len() < scene.lights.len() {
            let shared = scene.photons.with_defaults().caustic.unwrap_or(0);
            parts.push(("photons.caustic".into(), shared));
        }
        let total: u64 = parts.iter().map(|p| u64::from(p.1)).sum();
        // One field over the limit is reported by `photon_count`.
        if own.is_empty()
            || total <= u64::from(MAX_PHOTONS)
            || parts.iter().any(|p| p.1 > MAX_PHOTONS)
        {
            return;
        }
        let list: Vec<String> = parts.iter().map(|(f, n)| format!("{f} {n}")).collect();
        let path = parts[own.len() - 1].0.clone();
        self.out.push(Diagnostic::error(path, format!(
            "the caustic map would hold {total} photons ({}), more than the {MAX_PHOTONS} one map may have (a map that size could need {:.1} GB)",
            list.join(" + "), total as f64 * 24.0 * 4.0 / 1e9)).with_help("every light's caustic photons go into one map: lower the counts, or use `ppm` passes for more"));
    }

    /// `p`: the stated settings over their defaults (only `max_radius` may be `None`).
    pub(super) fn photons(&mut self, p: &PhotonSettings) {
        for (path, n) in [("photons.global", p.global), ("photons.caustic", p.caustic)] {
            if let Some(n) = n {
                self.photon_count(path, n);
            }
        }
        for (field, k) in [("gather", p.gather), ("caustic_gather", p.caustic_gather)] {
            if let Some(k) = k
                && (k == 0 || k > MAX_GATHER)
            {
                self.err(
                    &format!("photons.{field}"),
                    format!("must be within [1, {MAX_GATHER}] photons, found {k}"),
                );
            }
        }
        if let Some(r) = p.max_radius {
            self.positive("photons.max_radius", r, "the radius");
        }
        if let Some(alpha) = p.alpha
            && self.finite("photons.alpha", alpha)
            && !(alpha > 0.0 && alpha < 1.0)
        {
            self.out.push(
                Diagnostic::error(
                    "photons.alpha",
                    format!("must be within (0, 1), found {alpha}"),
                )
                .with_help("Knaus and Zwicker suggest 2/3: each pass keeps (i + α)/(i + 1) of the previous radius²"),
            );
        }
        if let Some(PhotonFilter::Cone { k }) = p.caustic_filter
            && self.finite("photons.caustic_filter.k", k)
            && !(1.0..=1e6).contains(&k)
        {
            self.out.push(
                Diagnostic::error(
                    "photons.caustic_filter.k",
                    format!("must be within [1, 1e6], found {k}"),
                )
                .with_help(
                    "k = 1 is the sharpest cone (weight 0 at the rim); larger k tends to `Box`",
                ),
            );
        }
        let (min, max) = (p.min_bounces.unwrap_or(1), p.max_bounces.unwrap_or(0));
        if p.min_bounces.is_some() && (min == 0 || min > max) {
            self.out.push(
                Diagnostic::error(
                    "photons.min_bounces",
                    format!("must be within [1, photons.max_bounces = {max}], found {min}"),
                )
                .with_help("direct light always comes from shadow rays, so the global map starts after at least one diffuse bounce"),
            );
        }
        if max > MAX_DEPTH {
            self.err(
                "photons.max_bounces",
                format!("must be at most {MAX_DEPTH}, found {max}"),
            );
        }
        if let Some(n) = p.final_gather
            && n > MAX_FINAL_GATHER
        {
            self.err(
                "photons.final_gather",
                format!("must be at most {MAX_FINAL_GATHER} rays per hit, found {n}"),
            );
        }
    }
}
