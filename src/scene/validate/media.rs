//! Checks of participating media (`media`, the scene's `medium`), of the media, priorities and
//! interfaces of materials (docs/media.md), and that the integrator renders them.

use super::*;
use crate::scene::schema::{LightSpec, MediumSpec};
use crate::settings::IntegratorKind;

impl<'a> Validator<'a> {
    /// Every medium's coefficients, the scene's `medium`, and the integrator.
    pub(super) fn media(&mut self, scene: &'a SceneFile) {
        for (name, m) in &scene.media {
            self.medium(&format!("media.{name}"), m);
        }
        if let Some(name) = &scene.medium {
            self.medium_ref("medium", name);
            // A scene-wide medium is unbounded: light from infinitely far away crosses an
            // infinite distance of it, so these lights add nothing (said, not silently dark).
            for (i, light) in scene.lights.iter().enumerate() {
                let kind = match light {
                    LightSpec::Distant { .. } => "a distant light",
                    LightSpec::Environment { .. } => "an environment",
                    LightSpec::Sky { .. } => "a sky",
                    LightSpec::Point { .. } | LightSpec::Spot { .. } | LightSpec::Sphere { .. } => {
                        continue;
                    }
                };
                self.out.push(
                    Diagnostic::warning(
                        format!("lights[{i}]"),
                        format!(
                            "{kind} is infinitely far away, and the scene-wide `medium` `{name}` fills all space: its light crosses an infinite distance of it and reaches nothing"
                        ),
                    )
                    .with_help("bound the fog with a closed surface of a material with `interface: true, medium: \"…\"` around the scene instead (docs/media.md)"),
                );
            }
        }
        let volumetric = scene.medium.is_some()
            || scene
                .materials
                .values()
                .any(|m| m.medium.is_some() || m.priority.is_some() || m.interface);
        if let Some(kind @ (IntegratorKind::Whitted | IntegratorKind::Photon)) =
            scene.render.integrator
            && volumetric
        {
            let what = scene
                .materials
                .iter()
                .find_map(|(n, m)| {
                    if m.medium.is_some() {
                        Some(format!("materials.{n}.medium"))
                    } else if m.priority.is_some() {
                        Some(format!("materials.{n}.priority"))
                    } else if m.interface {
                        Some(format!("materials.{n}.interface"))
                    } else {
                        None
                    }
                })
                .unwrap_or_else(|| "medium".to_string());
            self.out.push(
                Diagnostic::error(
                    "render.integrator",
                    format!(
                        "the `{kind:?}` integrator does not render participating media or nested dielectrics, which this scene uses (`{what}`)"
                    ),
                )
                .with_help("use `Path`, `Ppm` or `PathPpm` (`--integrator path`), or leave `integrator` out for the default estimator"),
            );
        }
    }

    /// One medium: a single form (coefficients or albedo and mean free path), each value in
    /// range, `g` in (−1, 1).
    fn medium(&mut self, path: &str, m: &MediumSpec) {
        let coeffs = m.sigma_a.is_some() || m.sigma_s.is_some();
        let albedo_form = m.albedo.is_some() || m.mean_free_path.is_some();
        let help =
            "give `sigma_a` and/or `sigma_s` per metre, or `albedo` with `mean_free_path` (metres)";
        if coeffs && albedo_form {
            self.out.push(
                Diagnostic::error(
                    path,
                    "a medium is given by its coefficients or by its albedo and mean free path, not both",
                )
                .with_help(help),
            );
        } else if albedo_form && (m.albedo.is_none() || m.mean_free_path.is_none()) {
            let missing = if m.albedo.is_none() {
                "albedo"
            } else {
                "mean_free_path"
            };
            self.out.push(
                Diagnostic::error(
                    format!("{path}.{missing}"),
                    format!("`albedo` and `mean_free_path` go together: `{missing}` is missing"),
                )
                .with_help(help),
            );
        } else if !coeffs && !albedo_form {
            self.out.push(
                Diagnostic::error(path, "the medium has no coefficients: it would be empty")
                    .with_help(help),
            );
        }
        for (field, v) in [("sigma_a", m.sigma_a), ("sigma_s", m.sigma_s)] {
            if let Some(v) = v {
                let p = format!("{path}.{field}");
                if self.finite3(&p, v) && v.iter().any(|x| *x < 0.0) {
                    self.err(
                        &p,
                        format!("coefficients must be ≥ 0 per metre, found {}", fmt3(v)),
                    );
                }
            }
        }
        if let Some(a) = m.albedo {
            self.unit_rgb(&format!("{path}.albedo"), a, "albedo");
        }
        if let Some(d) = m.mean_free_path {
            let p = format!("{path}.mean_free_path");
            if self.finite3(&p, d) && d.iter().any(|x| !(*x > 0.0)) {
                self.err(
                    &p,
                    format!("mean free paths must be > 0 metres, found {}", fmt3(d)),
                );
            }
        }
        if self.finite(&format!("{path}.g"), m.g) && !(m.g > -1.0 && m.g < 1.0) {
            self.err(
                &format!("{path}.g"),
                format!(
                    "the Henyey–Greenstein g must be within (−1, 1) (exclusive), found {}",
                    m.g
                ),
            );
        }
    }

    /// `name` is one of the scene's media.
    fn medium_ref(&mut self, path: &str, name: &str) {
        if self.scene.media.contains_key(name) {
            return;
        }
        let names = self.scene.media.keys().map(String::as_str);
        let list = quoted_list(names.clone());
        let mut d = Diagnostic::error(
            path,
            format!(
                "unknown medium `{name}`; defined media: {}",
                if list.is_empty() { "none" } else { &list }
            ),
        );
        if let Some(s) = did_you_mean(name, names) {
            d = d.with_help(format!("did you mean `{s}`?"));
        } else {
            d = d.with_help(
                "define it under `media`, e.g. `media: { \"fog\": (sigma_s: (0.1, 0.1, 0.1)) }`",
            );
        }
        self.out.push(d);
    }

    /// A material's `medium`, `priority` and `interface`.
    pub(super) fn material_volume(&mut self, path: &str, m: &MaterialSpec) {
        if let Some(name) = &m.medium {
            self.medium_ref(&format!("{path}.medium"), name);
            if m.absorption.is_some() {
                self.out.push(
                    Diagnostic::error(
                        format!("{path}.absorption"),
                        "`absorption` and `medium` cannot both be set: the medium's `sigma_a` is its absorption",
                    )
                    .with_help("move the absorption coefficients into the medium's `sigma_a`"),
                );
            }
        }
        let transmits = m.transmit.is_some_and(|w| w > 0.0);
        if m.interface {
            if m.medium.is_none() {
                self.out.push(
                    Diagnostic::error(
                        format!("{path}.interface"),
                        "an interface is only the boundary of a medium, but `medium` is not set",
                    )
                    .with_help("add `medium: \"name\"`, or remove `interface`"),
                );
            }
            let surface = [
                ("diffuse", m.diffuse.is_some()),
                ("reflect", m.reflect.is_some()),
                ("transmit", m.transmit.is_some()),
                ("coat", m.coat.is_some()),
                ("conductor", m.conductor.is_some()),
                ("absorption", m.absorption.is_some()),
                ("bump", m.bump.is_some()),
                ("normal_map", m.normal_map.is_some()),
                ("roughness", m.roughness != Default::default()),
                (
                    "color",
                    !matches!(m.color, ColorSpec::Rgb(c) if c == [0.8; 3]),
                ),
            ];
            for (field, set) in surface {
                if set {
                    self.out.push(
                        Diagnostic::error(
                            format!("{path}.{field}"),
                            format!(
                                "an interface has no surface, so `{field}` means nothing on it"
                            ),
                        )
                        .with_help("remove it, or remove `interface` to make a visible surface"),
                    );
                }
            }
        } else if m.priority.is_some() && !transmits && m.medium.is_none() {
            self.out.push(
                Diagnostic::error(
                    format!("{path}.priority"),
                    "a priority ranks the volumes that transmitting materials or media enclose, but this material neither transmits nor has a `medium`",
                )
                .with_help("remove `priority`, or give the material `transmit` or a `medium`"),
            );
        } else if m.medium.is_some() && !transmits {
            self.out.push(
                Diagnostic::error(
                    format!("{path}.medium"),
                    "light enters this medium only through a transmitting surface, but `transmit` is 0",
                )
                .with_help("give the material `transmit: 1` (a dielectric), or make it `interface: true` (no surface)"),
            );
        }
    }
}
