//! Checks of materials and textures, and of the textures a material names.

use super::*;
use crate::scene::schema::{AbsorptionSpec, CONDUCTOR_PRESETS, ConductorSpec, RoughnessSpec};

impl<'a> Validator<'a> {
    pub(super) fn material(&mut self, path: &str, m: &'a MaterialSpec) {
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
        if let Some(name) = &m.normal_map {
            self.texture_ref(&format!("{path}.normal_map"), name, TextureUse::Normal);
            if m.bump.is_some() {
                self.out.push(
                    Diagnostic::error(
                        format!("{path}.normal_map"),
                        "`normal_map` and `bump` cannot both be set: each replaces the shading normal",
                    )
                    .with_help("keep one: `bump` for a height source, or `normal_map` for a NormalMap texture"),
                );
            }
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
        self.microfacets(path, m);
        self.coat(path, m);
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

    /// Roughness in [0, 1], a known conductor or tint colours in [0, 1], and a valid
    /// absorption (the rules of `shading::absorption`, whose error text is reported).
    fn microfacets(&mut self, path: &str, m: &'a MaterialSpec) {
        let rough = match &m.roughness {
            RoughnessSpec::Isotropic(r) => vec![(format!("{path}.roughness"), *r)],
            RoughnessSpec::Anisotropic([x, y]) => vec![
                (format!("{path}.roughness[0]"), *x),
                (format!("{path}.roughness[1]"), *y),
            ],
            RoughnessSpec::Texture(name) => {
                self.texture_ref(&format!("{path}.roughness"), name, TextureUse::Color);
                Vec::new()
            }
        };
        for (p, r) in rough {
            if self.finite(&p, r) && !(0.0..=1.0).contains(&r) {
                self.out.push(
                    Diagnostic::error(&p, format!("roughness must be in [0, 1], found {r}"))
                        .with_help("0 is a perfect mirror or smooth glass, 0.1 polished, 0.3 brushed or frosted, 1 very rough; the GGX width is α = roughness²"),
                );
            }
        }
        match &m.conductor {
            None => {}
            Some(ConductorSpec::Preset(name)) if !CONDUCTOR_PRESETS.contains(&name.as_str()) => {
                let p = format!("{path}.conductor");
                let mut d = Diagnostic::error(
                    &p,
                    format!(
                        "unknown conductor `{name}`; the presets are {}",
                        quoted_list(CONDUCTOR_PRESETS)
                    ),
                );
                d = match did_you_mean(name, CONDUCTOR_PRESETS) {
                    Some(s) => d.with_help(format!("did you mean `{s}`?")),
                    None => d.with_help(
                        "or give an artist's colours: `conductor: (f0: (r, g, b), tint: (r, g, b))`",
                    ),
                };
                self.out.push(d);
            }
            Some(ConductorSpec::Preset(_)) => {}
            Some(ConductorSpec::Tint(t)) => {
                self.unit_rgb(&format!("{path}.conductor.f0"), t.f0, "f0");
                self.unit_rgb(&format!("{path}.conductor.tint"), t.tint, "tint");
            }
        }
        let Some(a) = &m.absorption else { return };
        let p = format!("{path}.absorption");
        let help = "give `absorption: (σr, σg, σb)` per metre, or `absorption: (color: (r, g, b), depth: d)`: the colour left after d metres";
        let before = self.out.len();
        match a {
            AbsorptionSpec::Coefficient(sigma) => {
                if self.finite3(&p, *sigma) && sigma.iter().any(|s| *s < 0.0) {
                    self.out.push(
                        Diagnostic::error(
                            &p,
                            format!(
                                "absorption coefficients must be ≥ 0 per metre, found {}",
                                fmt3(*sigma)
                            ),
                        )
                        .with_help(help),
                    );
                }
            }
            AbsorptionSpec::ColorAtDepth(c) => {
                let pc = format!("{p}.color");
                if self.finite3(&pc, c.color) && c.color.iter().any(|x| !(*x > 0.0 && *x <= 1.0)) {
                    self.out.push(
                        Diagnostic::error(
                            &pc,
                            format!(
                                "the colour left at the depth must be in (0, 1] per channel, found {}",
                                fmt3(c.color)
                            ),
                        )
                        .with_help(help),
                    );
                }
                self.positive(&format!("{p}.depth"), c.depth, "the depth");
            }
        }
        if self.out.len() == before && m.transmit.is_none_or(|w| w <= 0.0) {
            self.out.push(Diagnostic::warning(
                &p,
                "absorption acts inside the dielectric part, but `transmit` is 0, so no light enters",
            ));
        }
    }

    /// A coat's index is finite and > 0, and the coat is the material's only specular part: the
    /// mirror, the dielectric, roughness, a conductor and the Phong highlight are refused beside
    /// it (each by the field that is set, with what to do instead).
    fn coat(&mut self, path: &str, m: &'a MaterialSpec) {
        let Some(coat) = &m.coat else { return };
        let p = format!("{path}.coat.ior");
        if self.finite(&p, coat.ior) && coat.ior <= 0.0 {
            self.out.push(
                Diagnostic::error(
                    &p,
                    format!(
                        "the coat's index of refraction must be greater than 0, found {}",
                        coat.ior
                    ),
                )
                .with_help("typical values: 1.5 for a glaze, acrylic or varnish, 1.33 for water"),
            );
        }
        let rough = match &m.roughness {
            crate::scene::schema::RoughnessSpec::Isotropic(r) => *r != 0.0,
            crate::scene::schema::RoughnessSpec::Anisotropic([x, y]) => *x != 0.0 || *y != 0.0,
            crate::scene::schema::RoughnessSpec::Texture(_) => true,
        };
        let clashes = [
            (
                "reflect",
                m.reflect.is_some(),
                "the coat is the material's mirror (its Fresnel reflection); remove `reflect`",
            ),
            (
                "transmit",
                m.transmit.is_some(),
                "a coated surface is opaque; for glass use `transmit` without `coat`",
            ),
            (
                "roughness",
                rough,
                "a rough (GGX) coat is not implemented; remove `roughness` for a smooth coat",
            ),
            (
                "conductor",
                m.conductor.is_some(),
                "a coated metal is not implemented; use `coat` over a diffuse `color`, or `conductor` without `coat`",
            ),
            (
                "specular",
                m.specular.iter().any(|s| *s != 0.0),
                "the coat gives the highlight (a sharp Fresnel reflection); remove `specular`",
            ),
        ];
        for (field, set, help) in clashes {
            if set {
                self.out.push(
                    Diagnostic::error(
                        format!("{path}.{field}"),
                        format!("`{field}` cannot be combined with `coat`: a coated material is a diffuse base under a smooth clear coat"),
                    )
                    .with_help(help),
                );
            }
        }
    }

    pub(super) fn texture(&mut self, path: &str, t: &TextureSpec) {
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
            TextureSpec::NormalMap {
                file: f,
                tile: t,
                strength,
                ..
            } => {
                file(self, f);
                tile(self, t);
                let p = format!("{path}.strength");
                if self.finite(&p, *strength) && *strength < 0.0 {
                    self.out.push(
                        Diagnostic::error(&p, format!("must not be negative, found {strength}"))
                            .with_help(
                                "0 flattens the map, 1 is as drawn, 2 doubles the tilt's tangent",
                            ),
                    );
                }
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

    pub(super) fn texture_ref(&mut self, path: &str, name: &'a str, usage: TextureUse) {
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
            TextureUse::Color | TextureUse::Bump if t.gives_normals() => self.out.push(
                Diagnostic::error(
                    path,
                    format!("texture `{name}` is a NormalMap, which gives normals, not {}", if usage == TextureUse::Color { "colours" } else { "heights" }),
                )
                .with_help(format!("use it as `normal_map: \"{name}\"`")),
            ),
            TextureUse::Normal if !t.gives_normals() => self.out.push(
                Diagnostic::error(
                    path,
                    format!("texture `{name}` is a {}, not a NormalMap", t.kind()),
                )
                .with_help(if t.gives_bump() {
                    format!("use a height source as `bump: \"{name}\"`, or define a `NormalMap(file: \"…\")` texture")
                } else {
                    "define a `NormalMap(file: \"…\")` texture and name it here".to_string()
                }),
            ),
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
}
