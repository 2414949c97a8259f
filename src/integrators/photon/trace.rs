//! Following one photon through the scene (Jensen 2001, ch. 5): the same BSDF as camera paths,
//! sampled in importance mode (no η² at refraction, Veach's adjoint shading-normal factor), so
//! photon estimates and path tracing converge to the same image.
//!
//! At each hit the BSDF picks a lobe in proportion to the material's normalised diffuse /
//! reflect / transmit weights times their albedos (Fresnel inside the transmitting part), and
//! Russian roulette keeps the photon with probability `q = min(1, max channel of the sample's
//! weight)`, dividing its flux by `q`: photons keep (almost) equal flux, as the report's
//! "photons either stick or go on". A weight above 1 (the adjoint factor at a bumped surface)
//! raises the flux, capped at [`MAX_FLUX_GROWTH`] times the emitted flux.

use glam::Vec3;

use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use crate::render_scene::participating::FreeFlight;
use crate::render_scene::{Interaction, Medium, RenderScene};
use crate::sampling::Sampler;
use crate::shading::TransportMode;
use crate::spatial::Photon;

use super::volume::VolumePhoton;

/// Largest factor by which a photon's flux may grow along its path (the adjoint shading-normal
/// factor can exceed 1 at grazing angles on bumped surfaces; Veach 1997 §5.3). Bounds the
/// worst photon's flux so one grazing photon cannot leave a bright spot.
pub const MAX_FLUX_GROWTH: f32 = 10.0;

/// Free flights drawn along each medium segment of a caustic path for the volume caustic map
/// ([`trace_photon_into`]), each storing a photon with `1/VOLUME_SAMPLES` of the flux where it
/// ends before the segment does: 4 times the volume photons of one draw for no more photon
/// paths, so the beam estimate's radius is `4^{−1/3}` ≈ 0.63 of one draw's at the same
/// noise. (On `tests/it/volume_caustics.rs` one draw with 1 000 caustic photons per pass left
/// the image 22 % dark after 192 passes, from discs reaching over the water's surface; 8 000
/// photons, 12 %: a bias in proportion to the radius.)
pub const VOLUME_SAMPLES: u32 = 4;

/// Most surfaces a photon may cross straight on (interfaces, false hits of nested volumes)
/// before it is dropped: a guard against a ray caught on one surface by rounding.
const MAX_SKIPPED: u32 = 1024;

/// Which map a photon path feeds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum MapKind {
    /// Light → specular⁺ → diffuse: stored once, where it first lands on a diffuse surface
    /// (with [`TraceSettings::near_specular`], near-specular glossy surfaces count as specular).
    Caustic,
    /// Every diffuse landing after at least `min_bounces` diffuse bounces.
    Global,
}

/// What happened to photon paths (per light, per map), summed over photons.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct TraceCounts {
    /// Photons emitted (including those whose emission direction carried no light).
    pub emitted: u64,
    /// Caustic photons whose first hit was an object with a mirror or dielectric part.
    pub reached_specular: u64,
    /// Photons stored (a path may store several in the global map).
    pub stored: u64,
    /// Volume photons stored (caustic paths scattering in a medium, [`trace_photon_into`]).
    pub volume_stored: u64,
    /// Total flux stored (W per channel).
    pub stored_flux: Vec3,
    /// Photon paths cut by `max_bounces` while they still carried flux.
    pub lost_at_depth: u64,
    /// Flux the paths cut by `max_bounces` would have stored had they gone on (W per channel):
    /// each cut path is traced on without storing, for up to another `max_bounces` bounces
    /// ([`trace_photon`]), and what it would have stored is summed here. This is the light the
    /// cap takes from the map (the flux a path carries when cut understates it: in a closed
    /// room of albedo ρ that photon would have been stored about 1/(1 − ρ) more times).
    pub lost_flux: Vec3,
}

impl TraceCounts {
    /// Adds `other` into `self`.
    pub fn add(&mut self, other: &TraceCounts) {
        self.emitted += other.emitted;
        self.reached_specular += other.reached_specular;
        self.stored += other.stored;
        self.volume_stored += other.volume_stored;
        self.stored_flux += other.stored_flux;
        self.lost_at_depth += other.lost_at_depth;
        self.lost_flux += other.lost_flux;
    }
}

/// Settings of photon paths.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TraceSettings {
    /// Which map the path feeds.
    pub kind: MapKind,
    /// Global map: diffuse bounces before a photon is stored (any bounces, mirror and glass
    /// ones too, with `any_bounce`).
    pub min_bounces: u32,
    /// Global map: count every bounce towards `min_bounces`, so the map also holds caustics.
    pub any_bounce: bool,
    /// Most bounces before a path is dropped.
    pub max_bounces: u32,
    /// The progressive pass whose independent photon streams to draw (`None`: the photon
    /// integrator's one set of maps).
    pub pass: Option<u32>,
    /// The widest GGX α at which a glossy surface is near-specular
    /// ([`crate::shading::Bsdf::is_near_specular`]): photons pass through such surfaces as
    /// through mirrors (caustic paths go on, nothing is stored there, the bounce is not a
    /// diffuse one). `None`: only delta lobes are specular (the photon integrator).
    pub near_specular: Option<f32>,
}

impl TraceSettings {
    /// True if photons pass a surface of BSDF `bsdf` as a specular one although it is glossy
    /// (near-specular under [`TraceSettings::near_specular`]).
    #[inline]
    #[must_use]
    pub fn treats_as_specular(&self, bsdf: &crate::shading::Bsdf) -> bool {
        self.near_specular.is_some_and(|a| bsdf.is_near_specular(a))
    }
}

/// Traces one photon from `ray` carrying `power`, appending what it stores to `out` and
/// counting into `counts`; random numbers come from `sampler` (started on this photon).
/// Russian roulette ends paths (unbiased); `max_bounces` is a safety net against paths that
/// never lose flux (closed white mirrors): a path still alive after it is counted as cut
/// (`lost_at_depth`) and traced on, storing nothing, for up to another `max_bounces` bounces to
/// measure what the cut takes away (`lost_flux`).
pub fn trace_photon(
    scene: &RenderScene,
    ray: Ray,
    power: Vec3,
    settings: TraceSettings,
    sampler: &mut Sampler,
    out: &mut Vec<Photon>,
    counts: &mut TraceCounts,
) {
    trace_photon_into(scene, ray, power, settings, sampler, out, None, counts);
}

/// [`trace_photon`], also storing **volume photons** into `volume` when given (the volume
/// caustic map, `volume.rs`): a caustic photon crossing a scattering medium after at least one
/// specular bounce draws [`VOLUME_SAMPLES`] free-flight distances along the segment, and where
/// one falls before the segment's end stores a photon with its flux times the free-flight
/// weight `σs T(t)/p(t)`, over [`VOLUME_SAMPLES`] (the flux scattered there, in expectation). The photon itself goes on unscattered with its
/// expected share `exp(−σt d)`, as without `volume`, so the surface caustic map keeps its
/// meaning. Global photons store no volume photons. With `volume` `None`, no random number
/// is drawn for it: the path is [`trace_photon`]'s.
#[allow(clippy::too_many_arguments)]
pub fn trace_photon_into(
    scene: &RenderScene,
    mut ray: Ray,
    mut power: Vec3,
    settings: TraceSettings,
    sampler: &mut Sampler,
    out: &mut Vec<Photon>,
    mut volume: Option<&mut Vec<VolumePhoton>>,
    counts: &mut TraceCounts,
) {
    let max_flux = power.max_element() * MAX_FLUX_GROWTH;
    let mut diffuse_bounces = 0u32;
    let mut bounces = 0u32;
    let mut medium = Medium::outside(scene);
    // Past `max_bounces`: the path is only followed to account for what it would have stored.
    let mut cut = false;
    let mut skipped = 0u32;
    loop {
        let mut textured = None;
        let mut nested = None;
        let mut it = scene.interact(&ray, |_| 0.0, &mut textured);
        if scene.volumetric {
            if let Some(m) = medium.participating(scene) {
                let len = ray.dir.length();
                let t_hit = match &it {
                    Interaction::Escaped => f32::INFINITY,
                    Interaction::Emitter(e) => e.hit.t * len,
                    Interaction::Surface(v) => v.hit.t * len,
                };
                if settings.kind == MapKind::Caustic {
                    // Light → specular⁺ scattering here: a volume photon where a free flight
                    // ends before the surface (its flux σs T(t)/p(t) of the photon's).
                    if bounces > 0
                        && !cut
                        && m.scatters()
                        && let Some(store) = volume.as_deref_mut()
                        && let Some(id) = medium.participating_index()
                    {
                        for _ in 0..VOLUME_SAMPLES {
                            let FreeFlight::Scatter { t, weight } =
                                m.sample_distance(t_hit, sampler.next_2d())
                            else {
                                continue;
                            };
                            let flux = power * weight / VOLUME_SAMPLES as f32;
                            if flux.is_finite() && flux.max_element() > 0.0 {
                                store.push(VolumePhoton {
                                    position: ray.origin + ray.dir * (t / len),
                                    direction: ray.dir / len,
                                    power: flux,
                                    medium: id,
                                });
                                counts.volume_stored += 1;
                            }
                        }
                    }
                    // Caustic photons are the light that crosses media without scattering
                    // (a scattered photon is no longer on a specular path): their expected
                    // share, exp(−σt d), instead of sampling events and dropping the scattered.
                    power *= m.transmittance(t_hit);
                } else {
                    match m.sample_distance(t_hit, sampler.next_2d()) {
                        FreeFlight::Pass { weight } => power *= weight,
                        FreeFlight::Scatter { t, weight } => {
                            // A bounce in the medium: a diffuse one for the maps (nothing is
                            // stored there), continued by the phase function.
                            let p = ray.origin + ray.dir * (t / len);
                            let s = m.phase.sample(ray.dir / len, sampler.next_2d());
                            let u_rr = sampler.next_1d();
                            diffuse_bounces += 1;
                            bounces += 1;
                            let q = weight.max_element().min(1.0);
                            if !(q > 0.0) || u_rr >= q {
                                return;
                            }
                            power *= weight / q;
                            if !power.is_finite() {
                                return;
                            }
                            let m = power.max_element();
                            if m > max_flux {
                                power *= max_flux / m;
                            }
                            if bounces > settings.max_bounces && !cut {
                                cut = true;
                                counts.lost_at_depth += 1;
                            }
                            if bounces > settings.max_bounces.saturating_mul(2) {
                                return;
                            }
                            ray = Ray::new(p, s.wi);
                            continue;
                        }
                    }
                }
            } else {
                power *= medium.transmittance(&ray, &it);
            }
            if let Interaction::Surface(v) = &mut it
                // Interfaces and surfaces inside a volume of higher priority are not there.
                && let Some(next) = medium.surface_step(scene, &ray, v, &mut nested)
            {
                skipped += 1;
                if skipped > MAX_SKIPPED {
                    return;
                }
                (ray, medium) = next;
                continue;
            }
        } else {
            // Beer–Lambert absorption along the segment just travelled (1 outside media).
            power *= medium.transmittance(&ray, &it);
        }
        let v = match it {
            Interaction::Surface(v) => v,
            // Escaped, or an emitter: it absorbs what reaches it.
            Interaction::Escaped | Interaction::Emitter(_) => return,
        };
        let (sp, wo, fr, bsdf) = (v.sp, v.wo, v.frame, v.bsdf);
        let dir = -wo;
        let near = settings.treats_as_specular(bsdf);
        if bounces == 0 && settings.kind == MapKind::Caustic {
            if !bsdf.has_delta() && !near {
                return; // Aimed at a target but blocked by a diffuse object.
            }
            counts.reached_specular += 1;
        }
        if bsdf.has_local() && !near {
            let store = match settings.kind {
                MapKind::Caustic => bounces > 0,
                MapKind::Global if settings.any_bounce => bounces >= settings.min_bounces,
                MapKind::Global => diffuse_bounces >= settings.min_bounces,
            };
            if store && cut {
                counts.lost_flux += power;
            } else if store {
                out.push(Photon::new(sp.p, dir, fr.ng, power));
                counts.stored += 1;
                counts.stored_flux += power;
            }
        }
        let u_lobe = sampler.defer_1d();
        let u = sampler.next_2d();
        let u_rr = sampler.next_1d();
        let u_lobe = bsdf.lobe_number(|| sampler.get_1d(u_lobe));
        let Some(s) = bsdf.sample(wo, u_lobe, u, &fr, TransportMode::Importance) else {
            return;
        };
        if !s.delta && !near {
            if settings.kind == MapKind::Caustic {
                return; // No longer a caustic path (and it was stored above if it landed).
            }
            diffuse_bounces += 1;
        }
        let q = s.weight.max_element().min(1.0);
        if !(q > 0.0) || u_rr >= q {
            return;
        }
        power *= s.weight / q;
        let m = power.max_element();
        if !power.is_finite() {
            return;
        }
        if m > max_flux {
            power *= max_flux / m;
        }
        bounces += 1;
        if bounces > settings.max_bounces && !cut {
            cut = true;
            counts.lost_at_depth += 1;
        }
        if bounces > settings.max_bounces.saturating_mul(2) {
            return;
        }
        medium = medium.after(scene, &v, s.wi);
        let origin = offset_ray_origin(sp.p, sp.p_error, fr.ng, s.wi);
        ray = Ray::new(origin, s.wi);
    }
}
