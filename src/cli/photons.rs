//! `caustic photons`: the stored photons drawn over a dim grey Whitted render of the scene, each
//! map in its own colour (caustic: orange, global: blue), brighter where more power landed on a
//! pixel. The first tool to reach for when a caustic looks wrong.
//!
//! Every photon is projected through the pinhole camera to the pixel it falls in (a one-pixel
//! splat into a [`SplatBuffer`], so the sums do not depend on thread count or order) if the
//! camera sees it: it lies in front of the camera and inside the image, on the side
//! of its surface the camera is on (its stored normal faces the eye), and nothing opaque blocks
//! the segment from the eye to it (a shadow ray that passes through objects with a transmitting
//! part: caustics under water or behind glass are drawn where they lie, as if the water did not
//! bend the view). Per map, each pixel sums the mean power of its
//! photons; the sum `s` is drawn with opacity `1 − exp(−s / s₉₅)`, where `s₉₅` is the 95th
//! percentile of the map's non-empty pixels, so dense regions saturate and lone photons stay
//! faint. The global map is drawn first and the caustic map over it.

use std::path::PathBuf;

use clap::Args;
use glam::Vec3;
use rayon::prelude::*;

use caustic::Error;
use caustic::geometry::Ray;
use caustic::integrators::photon::PhotonMap;
use caustic::integrators::photon::cache::build_or_load;
use caustic::integrators::splat::SplatBuffer;
use caustic::pipeline::prepare;
use caustic::render::output::{OutputFormat, check_writable, srgb_encode, write_image};
use caustic::render::{Film, RenderOptions, render};
use caustic::render_scene::{IntegratorKind, RenderScene};
use caustic::texture::srgb_to_linear;

use super::{SceneArgs, print_warnings};

/// Colour of caustic-map photons (display values).
pub const CAUSTIC_COLOUR: Vec3 = Vec3::new(1.0, 0.55, 0.08);
/// Colour of global-map photons (display values).
pub const GLOBAL_COLOUR: Vec3 = Vec3::new(0.15, 0.45, 1.0);
/// Brightness of the grey base render (display values are scaled by this).
const BASE_DIM: f32 = 0.35;
/// Most samples per pixel of the base render.
const BASE_SPP: u32 = 4;

/// Arguments of `caustic photons`.
#[derive(Args)]
pub struct PhotonsArgs {
    #[command(flatten)]
    scene: SceneArgs,
    /// Output image (.png, or .exr for the same display values linearised).
    #[arg(short, long)]
    output: PathBuf,
    /// No warnings and no photon-map summary.
    #[arg(short, long)]
    quiet: bool,
    /// Read the photon maps from this folder, or save them there (as `render --photon-cache`).
    #[arg(long, value_name = "DIR")]
    photon_cache: Option<PathBuf>,
}

/// Builds (or loads) the maps, renders the base image and writes the view.
pub fn run(args: &PhotonsArgs) -> Result<(), Error> {
    OutputFormat::for_path(&args.output)?;
    check_writable(&args.output)?;
    let mut prepared = prepare(&args.scene.scene, &args.scene.overrides())?;
    if !args.quiet {
        print_warnings(&prepared.warnings);
    }
    let maps = build_or_load(&prepared.render_scene, args.photon_cache.as_deref(), None);
    if !args.quiet {
        eprintln!("{}", maps.summary);
    }
    let scene = &mut prepared.render_scene;
    let exposure = scene.params.exposure;
    scene.params.integrator = IntegratorKind::Whitted;
    scene.params.samples_per_pixel = scene.params.samples_per_pixel.clamp(1, BASE_SPP);
    let base = render(scene, &RenderOptions::default())?.film;
    let scene = &prepared.render_scene;
    let mut display: Vec<Vec3> = base
        .pixels
        .iter()
        .map(|&l| {
            let grey = (l * exposure).dot(Vec3::new(0.2126, 0.7152, 0.0722));
            let grey = if grey.is_finite() {
                grey.clamp(0.0, 1.0)
            } else {
                0.0
            };
            Vec3::splat(srgb_encode(grey) * BASE_DIM)
        })
        .collect();
    let mut drawn = [0usize; 2];
    for (i, (map, colour)) in [
        (&maps.global, GLOBAL_COLOUR),
        (&maps.caustic, CAUSTIC_COLOUR),
    ]
    .into_iter()
    .enumerate()
    {
        if let Some(map) = map {
            let sums = splat(scene, map);
            drawn[i] = sums.1;
            overlay(&mut display, &sums.0, colour);
        }
    }
    let film = Film {
        width: base.width,
        height: base.height,
        pixels: display
            .iter()
            .map(|d| Vec3::from_array(d.to_array().map(srgb_to_linear)))
            .collect(),
    };
    write_image(&film, &args.output, 1.0)?;
    let total = |m: &Option<PhotonMap>| m.as_ref().map_or(0, PhotonMap::len);
    println!(
        "{}: {}×{}, {} of {} caustic and {} of {} global photons visible",
        args.output.display(),
        film.width,
        film.height,
        drawn[1],
        total(&maps.caustic),
        drawn[0],
        total(&maps.global)
    );
    Ok(())
}

/// The pixel `(x, y)` the camera sees `p` in, if it sees it: in front, inside the image, on the
/// side of `normal` the eye is on, and not blocked.
fn visible_pixel(scene: &RenderScene, p: Vec3, normal: Vec3) -> Option<(u32, u32)> {
    let cam = &scene.camera;
    let (w, h) = (scene.params.width, scene.params.height);
    let d = p - cam.eye;
    let z = d.dot(cam.forward);
    if z <= 0.0 || normal.dot(-d) <= 0.0 {
        return None;
    }
    let dir = d / z;
    let u = dir.dot(cam.right) / cam.right.length_squared();
    let v = dir.dot(cam.up) / cam.up.length_squared();
    let fx = (u + 1.0) * 0.5 * w as f32;
    let fy = (1.0 - v) * 0.5 * h as f32;
    if !(fx >= 0.0 && fy >= 0.0 && fx < w as f32 && fy < h as f32) {
        return None;
    }
    // Opaque blockers strictly between the eye and the photon's surface (1 mm per metre of
    // margin); glass and water are looked through, without bending the line of sight.
    let ray = Ray {
        origin: cam.eye,
        dir: d,
        t_max: 0.999,
    };
    if scene
        .geometry
        .occluded_by(&ray, |prim| scene.is_opaque(scene.geometry.object_of(prim)))
    {
        return None;
    }
    Some((fx as u32, fy as u32))
}

/// Per pixel (row-major), the summed mean power (W) of the map's visible photons, and how many
/// were visible. Each visible photon splats its mean power (as grey) into a [`SplatBuffer`]
/// from the worker that found it visible: the buffer's exact fixed-point sums make the result
/// the same for any thread count and order.
fn splat(scene: &RenderScene, map: &PhotonMap) -> (Vec<f32>, usize) {
    let (w, h) = (scene.params.width, scene.params.height);
    let mut splats = SplatBuffer::new(w, h);
    let drawn = map
        .photons()
        .par_iter()
        .filter(|ph| {
            let power = ph.power();
            visible_pixel(scene, ph.position(), ph.normal())
                .map(|(x, y)| splats.add(x, y, Vec3::splat((power.x + power.y + power.z) / 3.0)))
                .is_some()
        })
        .count();
    let sums = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| splats.sum(x, y).x)
        .collect();
    (sums, drawn)
}

/// Draws `sums` over `display` in `colour` (module docs for the opacity).
fn overlay(display: &mut [Vec3], sums: &[f32], colour: Vec3) {
    let mut nonzero: Vec<f32> = sums.iter().copied().filter(|&s| s > 0.0).collect();
    if nonzero.is_empty() {
        return;
    }
    nonzero.sort_by(f32::total_cmp);
    let scale = nonzero[(nonzero.len() - 1) * 95 / 100].max(f32::MIN_POSITIVE);
    for (d, &s) in display.iter_mut().zip(sums) {
        if s > 0.0 {
            let a = 1.0 - (-s / scale).exp();
            *d = *d * (1.0 - a) + colour * a;
        }
    }
}
