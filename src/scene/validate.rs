//! Semantic checks of a parsed scene: every problem is reported, not just the first.

use std::collections::BTreeSet;

use super::diagnostic::{Diagnostic, did_you_mean, quoted_list};
use super::schema::{
    CameraSpec, ColorSpec, LightSpec, MaterialSpec, NodeSpec, PhotonFilter, PhotonSettings,
    RenderSettings, SceneFile, TextureSpec, TransformStep,
};

/// Largest accepted image side, in pixels.
pub const MAX_IMAGE_SIDE: u32 = 32_768;
/// Largest accepted image area, in pixels (the film needs 12 bytes per pixel).
pub const MAX_IMAGE_PIXELS: u64 = 100_000_000;
/// Largest accepted samples per pixel.
pub const MAX_SAMPLES_PER_PIXEL: u32 = 1 << 20;
/// Largest accepted recursion depth.
pub const MAX_DEPTH: u32 = 1024;
/// Deepest accepted group nesting.
pub const MAX_NESTING: usize = 64;
/// Most noise octaves accepted (each halves the feature size; 24 reach below f32 precision).
pub const MAX_OCTAVES: u32 = 24;
/// Highest frequency (per world or uv unit) the finest octave of a noise or marble texture may
/// reach: finer detail than a millionth of a unit is never visible, and far beyond it the
/// noise lattice runs out of f32 precision.
pub const MAX_NOISE_FREQUENCY: f32 = 1e6;
/// Largest marble turbulence (radians of phase).
pub const MAX_TURBULENCE: f32 = 1e4;

/// Largest light power, in watts per channel: f32 reaches 3.4e38, and radiance sums over samples,
/// bounces and pixels need headroom; any scene brighter than this renders the same with every
/// power divided by a constant and `render.exposure` multiplied by it.
pub const MAX_LIGHT_POWER: f32 = 1e30;

/// Most photons one map may be given: each emitted photon may be stored a few times (once per
/// diffuse bounce), at 24 bytes each, so this bounds a map to a few GB.
pub const MAX_PHOTONS: u32 = 50_000_000;
/// Most photons one density estimate may gather.
pub const MAX_GATHER: u32 = 10_000;
/// Most final-gather rays per camera hit.
pub const MAX_FINAL_GATHER: u32 = 4096;

/// Most ripple centres per texture.
pub const MAX_RIPPLE_CENTERS: usize = 256;

/// What a material uses a texture for.
#[derive(Clone, Copy, PartialEq, Eq)]
enum TextureUse {
    Color,
    Bump,
}

/// Checks a scene and returns all errors and warnings (errors first keep the file order).
#[must_use]
pub fn validate(scene: &SceneFile) -> Vec<Diagnostic> {
    let mut v = Validator {
        out: Vec::new(),
        used: BTreeSet::new(),
        used_textures: BTreeSet::new(),
        scene,
    };
    v.render(&scene.render);
    v.photons(&scene.photons);
    v.camera(&scene.camera);
    for (name, t) in &scene.textures {
        v.texture(&format!("textures.{name}"), t);
    }
    for (name, m) in &scene.materials {
        v.material(&format!("materials.{name}"), m);
    }
    if scene.lights.is_empty() {
        v.out.push(
            Diagnostic::warning(
                "lights",
                "the scene has no lights, so only the background will be visible",
            )
            .with_help("add e.g. `Point(position: (0, 5, 0), power: (100, 100, 100))`"),
        );
    }
    for (i, l) in scene.lights.iter().enumerate() {
        v.light(&format!("lights[{i}]"), l);
        if let Some(n) = l.caustic_photons() {
            v.photon_count(&format!("lights[{i}].caustic_photons"), n);
        }
    }
    v.caustic_map_total(scene);
    if scene.nodes.is_empty() {
        v.out.push(Diagnostic::error(
            "nodes",
            "the scene has no nodes, so there is nothing to render",
        ));
    }
    for (i, n) in scene.nodes.iter().enumerate() {
        v.node(&format!("nodes[{i}]"), n, 1);
    }
    // Unused materials are worth a warning only in a scene that is otherwise valid.
    let dangling_refs = v.out.iter().any(Diagnostic::is_error);
    for name in scene.materials.keys() {
        if !dangling_refs && !v.used.contains(name.as_str()) {
            v.out.push(Diagnostic::warning(
                format!("materials.{name}"),
                format!("material `{name}` is never used"),
            ));
        }
    }
    // A texture counts as used when some material refers to it, used or not: the material's
    // own warning already says it is unused.
    for name in scene.textures.keys() {
        if !dangling_refs && !v.used_textures.contains(name.as_str()) {
            v.out.push(Diagnostic::warning(
                format!("textures.{name}"),
                format!("texture `{name}` is never used, so it is not loaded"),
            ));
        }
    }
    v.out
}

struct Validator<'a> {
    out: Vec<Diagnostic>,
    used: BTreeSet<&'a str>,
    used_textures: BTreeSet<&'a str>,
    scene: &'a SceneFile,
}

impl<'a> Validator<'a> {
    fn err(&mut self, path: &str, msg: String) {
        self.out.push(Diagnostic::error(path, msg));
    }

    fn finite(&mut self, path: &str, v: f32) -> bool {
        if v.is_finite() {
            return true;
        }
        self.err(path, format!("must be a finite number, found {v}"));
        false
    }

    fn finite3(&mut self, path: &str, v: [f32; 3]) -> bool {
        if v.iter().all(|x| x.is_finite()) {
            return true;
        }
        self.err(
            path,
            format!("must have finite components, found {}", fmt3(v)),
        );
        false
    }

    fn positive(&mut self, path: &str, v: f32, what: &str) {
        if self.finite(path, v) && v <= 0.0 {
            self.err(path, format!("{what} must be greater than 0, found {v}"));
        }
    }

    fn range(&mut self, path: &str, v: f32, lo: f32, hi: f32) {
        if self.finite(path, v) && !(lo..=hi).contains(&v) {
            self.err(path, format!("must be within [{lo}, {hi}], found {v}"));
        }
    }

    fn unit_rgb(&mut self, path: &str, v: [f32; 3], what: &str) {
        if self.finite3(path, v) && v.iter().any(|c| !(0.0..=1.0).contains(c)) {
            self.out.push(
                Diagnostic::error(
                    path,
                    format!("{what} components must be within [0, 1], found {}", fmt3(v)),
                )
                .with_help(
                    "a reflectance above 1 would create energy; scale the light's power instead",
                ),
            );
        }
    }

    fn render(&mut self, r: &RenderSettings) {
        for (field, v) in [("width", r.width), ("height", r.height)] {
            let path = format!("render.{field}");
            if v == 0 {
                self.err(&path, "must be at least 1 pixel, found 0".into());
            } else if v > MAX_IMAGE_SIDE {
                self.err(
                    &path,
                    format!("must be at most {MAX_IMAGE_SIDE} pixels, found {v}"),
                );
            }
        }
        let pixels = u64::from(r.width) * u64::from(r.height);
        if r.width <= MAX_IMAGE_SIDE && r.height <= MAX_IMAGE_SIDE && pixels > MAX_IMAGE_PIXELS {
            self.err(
                "render.width",
                format!(
                    "{}×{} = {pixels} pixels exceeds the limit of {MAX_IMAGE_PIXELS} pixels (the film alone would need {:.1} GB)",
                    r.width,
                    r.height,
                    pixels as f64 * 12.0 / 1e9
                ),
            );
        }
        if r.samples_per_pixel == 0 || r.samples_per_pixel > MAX_SAMPLES_PER_PIXEL {
            self.err(
                "render.samples_per_pixel",
                format!(
                    "must be within [1, {MAX_SAMPLES_PER_PIXEL}], found {}",
                    r.samples_per_pixel
                ),
            );
        }
        if r.max_depth > MAX_DEPTH {
            self.err(
                "render.max_depth",
                format!("must be at most {MAX_DEPTH}, found {}", r.max_depth),
            );
        }
        if r.light_samples == 0 || r.light_samples > 1024 {
            self.err(
                "render.light_samples",
                format!("must be within [1, 1024], found {}", r.light_samples),
            );
        }
        self.range("render.min_contribution", r.min_contribution, 0.0, 1.0);
        if self.finite3("render.background", r.background) && r.background.iter().any(|c| *c < 0.0)
        {
            self.err(
                "render.background",
                format!("must not be negative, found {}", fmt3(r.background)),
            );
        }
        self.positive("render.exposure", r.exposure, "exposure");
    }

    fn camera(&mut self, c: &CameraSpec) {
        let CameraSpec::Pinhole {
            eye,
            look_at,
            up,
            fov_y,
        } = c;
        let ok = self.finite3("camera.eye", *eye)
            & self.finite3("camera.look_at", *look_at)
            & self.finite3("camera.up", *up);
        if self.finite("camera.fov_y", *fov_y) && !(*fov_y > 0.0 && *fov_y < 180.0) {
            self.err(
                "camera.fov_y",
                format!("must be within (0, 180) degrees, found {fov_y}"),
            );
        }
        if !ok {
            return;
        }
        let forward = glam::Vec3::from(*look_at) - glam::Vec3::from(*eye);
        if !(forward.length_squared() > 0.0) {
            self.err(
                "camera.look_at",
                format!("must differ from `eye`, both are {}", fmt3(*eye)),
            );
        } else if !(forward
            .normalize()
            .cross(glam::Vec3::from(*up))
            .length_squared()
            > 1e-12)
        {
            self.err(
                "camera.up",
                format!(
                    "must not be parallel to the view direction, found {}",
                    fmt3(*up)
                ),
            );
        }
    }

    fn material(&mut self, path: &str, m: &'a MaterialSpec) {
        let color = match &m.color {
            ColorSpec::Rgb(c) => {
                self.unit_rgb(&format!("{path}.color"), *c, "color");
                Some(*c)
            }
            ColorSpec::Texture(name) => {
                self.texture_ref(&format!("{path}.color"), name, TextureUse::Color);
                None
            }
        };
        if let Some(name) = &m.bump {
            self.texture_ref(&format!("{path}.bump"), name, TextureUse::Bump);
        }
        self.unit_rgb(&format!("{path}.specular"), m.specular, "specular");
        if self.finite(&format!("{path}.shininess"), m.shininess) && m.shininess < 0.0 {
            self.err(
                &format!("{path}.shininess"),
                format!("must not be negative, found {}", m.shininess),
            );
        }
        let weights = [
            ("diffuse", m.diffuse),
            ("reflect", m.reflect),
            ("transmit", m.transmit),
        ];
        let mut all_ok = true;
        for (field, w) in weights {
            let Some(w) = w else { continue };
            let p = format!("{path}.{field}");
            if !self.finite(&p, w) {
                all_ok = false;
            } else if w < 0.0 {
                all_ok = false;
                self.err(&p, format!("weights must not be negative, found {w}"));
            }
        }
        let any_given = weights.iter().any(|(_, w)| w.is_some());
        let sum: f32 = weights.iter().filter_map(|(_, w)| *w).sum();
        if all_ok && any_given && sum <= 0.0 {
            self.out.push(
                Diagnostic::error(path, "`diffuse`, `reflect` and `transmit` are all zero, so the surface would be black")
                    .with_help("give at least one weight a positive value; weights are normalised to sum to 1"),
            );
        }
        let p = format!("{path}.ior");
        if self.finite(&p, m.ior) && m.ior <= 0.0 {
            self.out.push(
                Diagnostic::error(
                    &p,
                    format!(
                        "index of refraction must be greater than 0, found {}",
                        m.ior
                    ),
                )
                .with_help("typical values: 1.0 air, 1.33 water, 1.5 glass, 2.42 diamond"),
            );
        }
        let Some(color) = color else { return };
        let gains = (0..3).any(|i| color[i] + m.specular[i] > 1.0 + 1e-6);
        if m.diffuse.unwrap_or(if any_given { 0.0 } else { 1.0 }) > 0.0
            && gains
            && color.iter().all(|c| c.is_finite())
        {
            self.out.push(Diagnostic::warning(
                format!("{path}.specular"),
                format!("color + specular exceeds 1 ({} + {}), so the surface reflects more light than it receives", fmt3(color), fmt3(m.specular)),
            ));
        }
    }

    fn texture(&mut self, path: &str, t: &TextureSpec) {
        let tile = |v: &mut Self, tile: &[f32; 2]| {
            for (i, s) in tile.iter().enumerate() {
                v.positive(&format!("{path}.tile[{i}]"), *s, "tile");
            }
        };
        let file = |v: &mut Self, file: &str| {
            if file.trim().is_empty() {
                v.err(
                    &format!("{path}.file"),
                    "must name an image file, found an empty string".into(),
                );
            }
        };
        let finest = |v: &mut Self, field: &str, f: f32, o: u32| {
            let top = f64::from(f.abs()) * 2f64.powi(o.max(1) as i32 - 1);
            // Too many octaves is its own error.
            if f.is_finite() && o <= MAX_OCTAVES && top > f64::from(MAX_NOISE_FREQUENCY) {
                v.err(
                    &format!("{path}.{field}"),
                    format!("with {o} octaves the finest octave has frequency {top:.3e} per unit, above the limit of {MAX_NOISE_FREQUENCY:e}"),
                );
            }
        };
        let octaves = |v: &mut Self, o: u32| {
            if o > MAX_OCTAVES {
                v.err(
                    &format!("{path}.octaves"),
                    format!("must be at most {MAX_OCTAVES}, found {o} (octaves beyond ~12 are finer than any pixel)"),
                );
            }
        };
        match t {
            TextureSpec::Bitmap {
                file: f, tile: t, ..
            } => {
                file(self, f);
                tile(self, t);
            }
            TextureSpec::HeightMap {
                file: f,
                depth,
                tile: t,
            } => {
                file(self, f);
                tile(self, t);
                self.finite(&format!("{path}.depth"), *depth);
            }
            TextureSpec::Marble {
                base,
                vein,
                frequency,
                octaves: o,
                turbulence,
                depth,
                ..
            } => {
                self.unit_rgb(&format!("{path}.base"), *base, "base");
                self.unit_rgb(&format!("{path}.vein"), *vein, "vein");
                let f = frequency.factors();
                if self.finite3(&format!("{path}.frequency"), f) {
                    let top = f.iter().fold(0.0f32, |a, x| a.max(x.abs()));
                    finest(self, "frequency", top, *o);
                }
                octaves(self, *o);
                if self.finite(&format!("{path}.turbulence"), *turbulence)
                    && turbulence.abs() > MAX_TURBULENCE
                {
                    self.err(
                        &format!("{path}.turbulence"),
                        format!("must be within ±{MAX_TURBULENCE}, found {turbulence:e}"),
                    );
                }
                self.finite(&format!("{path}.depth"), *depth);
            }
            TextureSpec::Noise {
                low,
                high,
                frequency,
                octaves: o,
                depth,
                ..
            } => {
                self.unit_rgb(&format!("{path}.low"), *low, "low");
                self.unit_rgb(&format!("{path}.high"), *high, "high");
                self.positive(&format!("{path}.frequency"), *frequency, "frequency");
                finest(self, "frequency", *frequency, *o);
                octaves(self, *o);
                if *o == 0 {
                    self.err(
                        &format!("{path}.octaves"),
                        "must be at least 1, found 0".into(),
                    );
                }
                self.finite(&format!("{path}.depth"), *depth);
            }
            TextureSpec::Ripple {
                centers,
                frequency,
                amplitude,
                decay,
            } => {
                for (i, c) in centers.iter().enumerate() {
                    let p = format!("{path}.centers[{i}]");
                    if !c.iter().all(|x| x.is_finite()) {
                        self.err(&p, format!("must be finite, found ({}, {})", c[0], c[1]));
                    }
                }
                if centers.is_empty() {
                    self.out.push(
                        Diagnostic::error(
                            format!("{path}.centers"),
                            "needs at least one centre, found none",
                        )
                        .with_help("centres are uv coordinates, e.g. `[(0.5, 0.5)]`"),
                    );
                }
                if centers.len() > MAX_RIPPLE_CENTERS {
                    self.err(
                        &format!("{path}.centers"),
                        format!("at most {MAX_RIPPLE_CENTERS} centres are allowed (each costs time at every shaded point), found {}", centers.len()),
                    );
                }
                self.positive(&format!("{path}.frequency"), *frequency, "frequency");
                self.finite(&format!("{path}.amplitude"), *amplitude);
                if self.finite(&format!("{path}.decay"), *decay) && *decay < 0.0 {
                    self.err(
                        &format!("{path}.decay"),
                        format!("must not be negative, found {decay}"),
                    );
                }
            }
        }
    }

    fn texture_ref(&mut self, path: &str, name: &'a str, usage: TextureUse) {
        let Some(t) = self.scene.textures.get(name) else {
            let names = self.scene.textures.keys().map(String::as_str);
            let list = quoted_list(names.clone());
            let mut d = Diagnostic::error(
                path,
                format!(
                    "unknown texture `{name}`; defined textures: {}",
                    if list.is_empty() { "none" } else { &list }
                ),
            );
            if let Some(s) = did_you_mean(name, names) {
                d = d.with_help(format!("did you mean `{s}`?"));
            } else if usage == TextureUse::Color {
                d = d.with_help("a colour is an RGB triple `(r, g, b)` or the name of a texture defined under `textures`");
            }
            self.out.push(d);
            return;
        };
        self.used_textures.insert(name);
        match usage {
            TextureUse::Color if !t.gives_color() => self.out.push(
                Diagnostic::error(
                    path,
                    format!(
                        "texture `{name}` is a {}, which gives heights, not colours",
                        t.kind()
                    ),
                )
                .with_help(format!("use it as `bump: \"{name}\"`, or give `color` a Bitmap, Marble or Noise texture")),
            ),
            TextureUse::Bump if !t.gives_bump() => self.out.push(
                Diagnostic::error(
                    path,
                    format!("texture `{name}` is a Bitmap, which gives colours, not heights"),
                )
                .with_help("bump with a HeightMap (a grey image with a `depth`), a Ripple, or a Noise or Marble with a `depth`"),
            ),
            _ => {}
        }
    }

    /// A photon count: at most [`MAX_PHOTONS`] (the map's memory is stated in the message).
    fn photon_count(&mut self, path: &str, n: u32) {
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
    fn caustic_map_total(&mut self, scene: &SceneFile) {
        let own: Vec<(usize, u32)> = (scene.lights.iter().enumerate())
            .filter_map(|(i, l)| l.caustic_photons().map(|n| (i, n)))
            .collect();
        let mut parts: Vec<(String, u32)> = (own.iter())
            .map(|&(i, n)| (format!("lights[{i}].caustic_photons"), n))
            .collect();
        if own.len() < scene.lights.len() {
            parts.push(("photons.caustic".into(), scene.photons.caustic));
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

    fn photons(&mut self, p: &PhotonSettings) {
        self.photon_count("photons.global", p.global);
        self.photon_count("photons.caustic", p.caustic);
        for (field, k) in [("gather", p.gather), ("caustic_gather", p.caustic_gather)] {
            if k == 0 || k > MAX_GATHER {
                self.err(
                    &format!("photons.{field}"),
                    format!("must be within [1, {MAX_GATHER}] photons, found {k}"),
                );
            }
        }
        if let Some(r) = p.max_radius {
            self.positive("photons.max_radius", r, "the radius");
        }
        if self.finite("photons.alpha", p.alpha) && !(p.alpha > 0.0 && p.alpha < 1.0) {
            self.out.push(
                Diagnostic::error(
                    "photons.alpha",
                    format!("must be within (0, 1), found {}", p.alpha),
                )
                .with_help("Knaus and Zwicker suggest 2/3: each pass keeps (i + α)/(i + 1) of the previous radius²"),
            );
        }
        if let PhotonFilter::Cone { k } = p.caustic_filter
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
        if p.min_bounces == 0 || p.min_bounces > p.max_bounces {
            self.out.push(
                Diagnostic::error(
                    "photons.min_bounces",
                    format!(
                        "must be within [1, photons.max_bounces = {}], found {}",
                        p.max_bounces, p.min_bounces
                    ),
                )
                .with_help("direct light always comes from shadow rays, so the global map starts after at least one diffuse bounce"),
            );
        }
        if p.max_bounces > MAX_DEPTH {
            self.err(
                "photons.max_bounces",
                format!("must be at most {MAX_DEPTH}, found {}", p.max_bounces),
            );
        }
        if p.final_gather > MAX_FINAL_GATHER {
            self.err(
                "photons.final_gather",
                format!(
                    "must be at most {MAX_FINAL_GATHER} rays per hit, found {}",
                    p.final_gather
                ),
            );
        }
    }

    fn light(&mut self, path: &str, l: &LightSpec) {
        let (power, power_path) = match l {
            LightSpec::Point {
                position, power, ..
            } => {
                self.finite3(&format!("{path}.position"), *position);
                (power, format!("{path}.power"))
            }
            LightSpec::Sphere {
                center,
                radius,
                power,
                ..
            } => {
                self.finite3(&format!("{path}.center"), *center);
                self.positive(&format!("{path}.radius"), *radius, "radius");
                (power, format!("{path}.power"))
            }
        };
        if self.finite3(&power_path, *power) && power.iter().any(|c| *c < 0.0) {
            self.err(
                &power_path,
                format!("must not be negative, found {}", fmt3(*power)),
            );
        } else if power.iter().any(|c| *c > MAX_LIGHT_POWER) {
            self.out.push(
                Diagnostic::error(
                    &power_path,
                    format!(
                        "must be at most {MAX_LIGHT_POWER:e} W per channel (single-precision radiance overflows beyond), found {}",
                        fmt3(*power)
                    ),
                )
                .with_help("divide every light's power by a constant and multiply `render.exposure` by it: the image is the same"),
            );
        }
    }

    fn node(&mut self, path: &str, n: &'a NodeSpec, depth: usize) {
        if depth > MAX_NESTING {
            self.err(
                path,
                format!("groups are nested more than {MAX_NESTING} levels deep"),
            );
            return;
        }
        for (i, step) in n.transform().iter().enumerate() {
            self.transform_step(&format!("{path}.transform[{i}]"), step);
        }
        if let Some(material) = n.material() {
            self.material_ref(&format!("{path}.material"), material);
        }
        match n {
            NodeSpec::Group { children, .. } => {
                for (i, c) in children.iter().enumerate() {
                    self.node(&format!("{path}.children[{i}]"), c, depth + 1);
                }
            }
            NodeSpec::Sphere { center, radius, .. } => {
                self.finite3(&format!("{path}.center"), *center);
                self.positive(&format!("{path}.radius"), *radius, "radius");
            }
            NodeSpec::Cube { size, .. } => self.positive(&format!("{path}.size"), *size, "size"),
            NodeSpec::Quad { size, .. } => {
                for (i, s) in size.iter().enumerate() {
                    self.positive(&format!("{path}.size[{i}]"), *s, "size");
                }
            }
            NodeSpec::Mesh {
                file,
                material,
                materials,
                ..
            } => {
                for (group, m) in materials {
                    let at = format!("{path}.materials.{group}");
                    if group.trim().is_empty() {
                        self.err(
                            &at,
                            "must name an OBJ group or `usemtl` name, found an empty string".into(),
                        );
                    }
                    self.material_ref(&at, m);
                }
                if material.is_none() && materials.is_empty() {
                    self.out.push(
                        Diagnostic::error(path, "a mesh needs a `material` (or `materials` for its OBJ groups), found neither")
                            .with_help("add `material: \"name\"`, or `materials: {\"group\": \"name\", ...}` mapping each OBJ group or `usemtl` name"),
                    );
                }
                if file.trim().is_empty() {
                    self.err(
                        &format!("{path}.file"),
                        "must name an OBJ file, found an empty string".into(),
                    );
                }
            }
        }
    }

    fn material_ref(&mut self, path: &str, name: &'a str) {
        if self.scene.materials.contains_key(name) {
            self.used.insert(name);
            return;
        }
        let names = self.scene.materials.keys().map(String::as_str);
        let list = quoted_list(names.clone());
        let mut d = Diagnostic::error(
            path,
            format!(
                "unknown material `{name}`; defined materials: {}",
                if list.is_empty() { "none" } else { &list }
            ),
        );
        if let Some(s) = did_you_mean(name, names) {
            d = d.with_help(format!("did you mean `{s}`?"));
        }
        self.out.push(d);
    }

    fn transform_step(&mut self, path: &str, step: &TransformStep) {
        match step {
            TransformStep::Translate(x, y, z) => {
                self.finite3(path, [*x, *y, *z]);
            }
            TransformStep::RotateX(a) | TransformStep::RotateY(a) | TransformStep::RotateZ(a) => {
                self.finite(path, *a);
            }
            TransformStep::Scale(s) => {
                let v = s.factors();
                if self.finite3(path, v) && v.contains(&0.0) {
                    self.out.push(
                        Diagnostic::error(
                            path,
                            format!(
                                "scale {} is singular (a zero factor flattens the object)",
                                fmt3(v)
                            ),
                        )
                        .with_help("use a small positive factor, or remove the node"),
                    );
                }
            }
        }
    }
}

/// Formats a triple as `(x, y, z)`.
#[must_use]
pub fn fmt3(v: [f32; 3]) -> String {
    format!("({}, {}, {})", v[0], v[1], v[2])
}
