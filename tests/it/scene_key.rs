//! The scene keys (`render_scene::hash`): the photon key (the photon cache's file name) and the
//! pixel key (the `.part` films' settings hash) change when any one field that decides pixels
//! changes, and stay put for what must not move them: the output path and the thread count
//! (neither), the image size, samples, camera and estimate-only photon settings (the photon
//! key). Checked by mutating one field of a compiled scene at a time (every listed field, to a
//! value proptest draws) and, for materials, by building random BSDFs through every constructor:
//! two BSDFs key alike exactly when they are equal.

use std::path::Path;
use std::sync::Arc;

use caustic::binfile::{Fnv, KeyHash};
use caustic::pipeline::{SceneOverrides, prepare};
use caustic::render_scene::hash::{photon_key, pixel_key};
use caustic::render_scene::light::rect::RectLight;
use caustic::render_scene::{Light, RenderScene, Texture};
use caustic::settings::{IntegratorKind, SamplerKind, TextureFilter, Tonemap};
use caustic::shading::Bsdf;
use caustic::shading::conductor::ConductorFresnel;
use caustic::shading::microfacet::Ggx;
use glam::Vec3;
use proptest::prelude::*;

use crate::common::{caustic, root};

fn scene(name: &str) -> RenderScene {
    prepare(
        &root().join("scenes").join(name),
        &SceneOverrides::default(),
    )
    .unwrap_or_else(|e| panic!("{name}: {e}"))
    .render_scene
}

/// A value different from `x` derived from the proptest number `t` ∈ [0, 1).
fn other(x: f32, t: f32) -> f32 {
    let y = x + 0.25 + t;
    if y == x { x + 1.0 } else { y }
}

fn other_v(v: Vec3, t: f32, axis: usize) -> Vec3 {
    let mut a = v.to_array();
    a[axis % 3] = other(a[axis % 3], t);
    Vec3::from_array(a)
}

/// Whether the photon key must change with the field (else only the pixel key).
#[derive(Clone, Copy, Debug, PartialEq)]
enum Reach {
    Photons,
    PixelsOnly,
}

/// One field of one compiled scene, changed to a value derived from `t` (`None` when the scene
/// has no such field).
type Mutation = fn(&mut RenderScene, f32) -> Option<Reach>;

const SCENES: [&str; 3] = ["materials.ron", "lights.ron", "noise.ron"];

fn first_light<T>(
    s: &mut RenderScene,
    pick: impl Fn(&mut Light) -> Option<&mut T>,
) -> Option<&mut T> {
    s.lights.iter_mut().find_map(pick)
}

/// Every mutation the property test draws from, by name.
fn mutations() -> Vec<(&'static str, Mutation)> {
    vec![
        ("params.width", |s, _| {
            s.params.width += 1;
            Some(Reach::PixelsOnly)
        }),
        ("params.height", |s, _| {
            s.params.height += 3;
            Some(Reach::PixelsOnly)
        }),
        ("params.samples_per_pixel", |s, _| {
            s.params.samples_per_pixel += 1;
            Some(Reach::PixelsOnly)
        }),
        ("params.max_depth", |s, _| {
            s.params.max_depth += 1;
            Some(Reach::PixelsOnly)
        }),
        ("params.min_contribution", |s, t| {
            s.params.min_contribution = other(s.params.min_contribution, t);
            Some(Reach::PixelsOnly)
        }),
        ("params.light_samples", |s, _| {
            s.params.light_samples += 1;
            Some(Reach::PixelsOnly)
        }),
        ("params.seed", |s, _| {
            s.params.seed += 1;
            Some(Reach::Photons)
        }),
        ("params.background", |s, t| {
            s.params.background = other_v(s.params.background, t, 1);
            Some(Reach::PixelsOnly)
        }),
        ("params.exposure", |s, t| {
            s.params.exposure = other(s.params.exposure, t);
            Some(Reach::PixelsOnly)
        }),
        ("params.tonemap", |s, _| {
            let i = Tonemap::ALL.iter().position(|t| *t == s.params.tonemap)?;
            s.params.tonemap = Tonemap::ALL[(i + 1) % Tonemap::ALL.len()];
            Some(Reach::PixelsOnly)
        }),
        ("params.integrator", |s, _| {
            let all = IntegratorKind::ALL;
            let i = all.iter().position(|t| *t == s.params.integrator)?;
            s.params.integrator = all[(i + 1) % all.len()];
            Some(Reach::PixelsOnly)
        }),
        ("params.sampler", |s, _| {
            let all = SamplerKind::ALL;
            let i = all.iter().position(|t| *t == s.params.sampler)?;
            s.params.sampler = all[(i + 1) % all.len()];
            Some(Reach::Photons)
        }),
        ("params.diffuse_depth", |s, _| {
            s.params.diffuse_depth = s.params.diffuse_depth.wrapping_add(1);
            Some(Reach::PixelsOnly)
        }),
        ("params.texture_filter", |s, _| {
            let all = TextureFilter::ALL;
            let i = all.iter().position(|t| *t == s.params.texture_filter)?;
            s.params.texture_filter = all[(i + 1) % all.len()];
            Some(Reach::Photons)
        }),
        ("photons.global", |s, _| {
            s.params.photons.global += 1;
            Some(Reach::Photons)
        }),
        ("photons.caustic", |s, _| {
            s.params.photons.caustic += 1;
            Some(Reach::Photons)
        }),
        ("photons.caustic_per_light", |s, _| {
            let slot = s.params.photons.caustic_per_light.first_mut()?;
            *slot = Some(slot.map_or(7, |n| n + 1));
            Some(Reach::Photons)
        }),
        ("photons.gather", |s, _| {
            s.params.photons.gather += 1;
            Some(Reach::PixelsOnly)
        }),
        ("photons.caustic_gather", |s, _| {
            s.params.photons.caustic_gather += 1;
            Some(Reach::PixelsOnly)
        }),
        ("photons.max_radius", |s, t| {
            s.params.photons.max_radius =
                Some(other(s.params.photons.max_radius.unwrap_or(0.0), t));
            Some(Reach::PixelsOnly)
        }),
        ("photons.alpha", |s, t| {
            s.params.photons.alpha = other(s.params.photons.alpha, t);
            Some(Reach::PixelsOnly)
        }),
        ("photons.caustic_cone", |s, t| {
            s.params.photons.caustic_cone =
                Some(other(s.params.photons.caustic_cone.unwrap_or(0.0), t));
            Some(Reach::PixelsOnly)
        }),
        ("photons.min_bounces", |s, _| {
            s.params.photons.min_bounces += 1;
            Some(Reach::Photons)
        }),
        ("photons.final_gather", |s, _| {
            s.params.photons.final_gather += 1;
            Some(Reach::PixelsOnly)
        }),
        ("photons.max_bounces", |s, _| {
            s.params.photons.max_bounces += 1;
            Some(Reach::Photons)
        }),
        ("camera.eye", |s, t| {
            s.camera.eye = other_v(s.camera.eye, t, 0);
            Some(Reach::PixelsOnly)
        }),
        ("camera.forward", |s, t| {
            s.camera.forward = other_v(s.camera.forward, t, 2);
            Some(Reach::PixelsOnly)
        }),
        ("camera.right", |s, t| {
            s.camera.right = other_v(s.camera.right, t, 0);
            Some(Reach::PixelsOnly)
        }),
        ("camera.up", |s, t| {
            s.camera.up = other_v(s.camera.up, t, 1);
            Some(Reach::PixelsOnly)
        }),
        ("camera.lens", |s, t| {
            s.camera = s.camera.with_thin_lens(0.01 + t, 2.0 + t);
            Some(Reach::PixelsOnly)
        }),
        ("material.color", |s, t| {
            let m = s.materials.first_mut()?;
            m.bsdf = m.bsdf.with_color(other_v(m.bsdf.color(), t, 0));
            Some(Reach::Photons)
        }),
        ("material.roughness", |s, t| {
            let m = s.materials.iter_mut().find(|m| m.bsdf.weights()[1] > 0.0)?;
            m.bsdf = m
                .bsdf
                .with_microfacets(Some(Ggx::new(0.05 + t * 0.5, 0.3)), None);
            Some(Reach::Photons)
        }),
        ("material.coat", |s, t| {
            let m = s.materials.first_mut()?;
            m.bsdf = m.bsdf.with_coat(Some(1.2 + t));
            Some(Reach::Photons)
        }),
        ("material.color_texture", |s, _| {
            let m = s.materials.first_mut()?;
            m.color_texture = Some(m.color_texture.map_or(0, |i| i + 1));
            Some(Reach::Photons)
        }),
        ("material.bump", |s, _| {
            let m = s.materials.first_mut()?;
            m.bump = Some(m.bump.map_or(0, |i| i + 1));
            Some(Reach::Photons)
        }),
        ("material.normal_map", |s, _| {
            let m = s.materials.first_mut()?;
            m.normal_map = Some(m.normal_map.map_or(0, |i| i + 1));
            Some(Reach::Photons)
        }),
        ("material.roughness_texture", |s, _| {
            let m = s.materials.first_mut()?;
            m.roughness_texture = Some(m.roughness_texture.map_or(0, |i| i + 1));
            Some(Reach::Photons)
        }),
        ("material.conductor", |s, t| {
            let m = s.materials.first_mut()?;
            m.conductor = Some(ConductorFresnel::schlick(Vec3::splat(0.2 + 0.5 * t)));
            Some(Reach::Photons)
        }),
        ("material.filtered", |s, _| {
            let m = s.materials.first_mut()?;
            m.filtered = !m.filtered;
            Some(Reach::Photons)
        }),
        ("material.absorption", |s, t| {
            let m = s.materials.first_mut()?;
            m.absorption =
                caustic::shading::absorption::Absorption::from_coefficient([0.5 + t; 3]).ok()?;
            Some(Reach::Photons)
        }),
        ("object.material", |s, _| {
            let o = s.objects.iter_mut().find(|o| o.material.is_some())?;
            o.material = o.material.map(|m| m + 1);
            Some(Reach::Photons)
        }),
        ("object.light", |s, _| {
            let o = s.objects.first_mut()?;
            o.light = Some(o.light.map_or(0, |l| l + 1));
            Some(Reach::Photons)
        }),
        ("texture.noise.frequency", |s, t| {
            s.textures.iter_mut().find_map(|x| match x {
                Texture::Noise(n) => {
                    n.frequency = other(n.frequency, t);
                    Some(Reach::Photons)
                }
                _ => None,
            })
        }),
        ("texture.marble.scale", |s, t| {
            s.textures.iter_mut().find_map(|x| match x {
                Texture::Marble { marble, .. } => {
                    marble.scale = other_v(marble.scale, t, 0);
                    Some(Reach::Photons)
                }
                _ => None,
            })
        }),
        ("texture.marble.depth", |s, t| {
            s.textures.iter_mut().find_map(|x| match x {
                Texture::Marble { depth, .. } => {
                    *depth = other(*depth, t);
                    Some(Reach::Photons)
                }
                _ => None,
            })
        }),
        ("texture.bitmap.tile", |s, t| {
            s.textures.iter_mut().find_map(|x| match x {
                Texture::Bitmap(b) => {
                    b.tile.x = other(b.tile.x, t);
                    Some(Reach::Photons)
                }
                _ => None,
            })
        }),
        ("light.point.intensity", |s, t| {
            let i = first_light(s, |l| match l {
                Light::Point { intensity, .. } => Some(intensity),
                _ => None,
            })?;
            *i = other_v(*i, t, 1);
            Some(Reach::Photons)
        }),
        ("light.sphere.radius", |s, t| {
            let r = first_light(s, |l| match l {
                Light::Sphere { radius, .. } => Some(radius),
                _ => None,
            })?;
            *r = other(*r, t);
            Some(Reach::Photons)
        }),
        ("light.rect.two_sided", |s, _| {
            let r: &mut RectLight = first_light(s, |l| match l {
                Light::Rect(r) => Some(r),
                _ => None,
            })?;
            r.two_sided = !r.two_sided;
            Some(Reach::Photons)
        }),
        ("light.rect.radiance", |s, t| {
            let r: &mut RectLight = first_light(s, |l| match l {
                Light::Rect(r) => Some(r),
                _ => None,
            })?;
            r.radiance = other_v(r.radiance, t, 2);
            Some(Reach::Photons)
        }),
        ("light.spot.cos_outer", |s, t| {
            let l = first_light(s, |l| match l {
                Light::Spot(x) => Some(x),
                _ => None,
            })?;
            l.cos_outer = other(l.cos_outer, t);
            Some(Reach::Photons)
        }),
        ("light.distant.one_minus_cos", |s, t| {
            let l = first_light(s, |l| match l {
                Light::Distant(x) => Some(x),
                _ => None,
            })?;
            l.one_minus_cos = other(l.one_minus_cos, t);
            Some(Reach::Photons)
        }),
        ("light.environment.rotation", |s, t| {
            let l = first_light(s, |l| match l {
                Light::Environment(x) => Some(x),
                _ => None,
            })?;
            Arc::make_mut(l).rotation.0 = other(l.rotation.0, t);
            Some(Reach::Photons)
        }),
        ("light.mesh.radiance", |s, t| {
            let l = first_light(s, |l| match l {
                Light::Mesh(x) => Some(x),
                _ => None,
            })?;
            let m = Arc::make_mut(l);
            m.radiance = other_v(m.radiance, t, 0);
            Some(Reach::Photons)
        }),
        ("geometry.triangle", |s, t| {
            let tri = s.geometry.triangles.first_mut()?;
            tri[1] = other_v(tri[1], t, 2);
            Some(Reach::Photons)
        }),
        ("geometry.tri_uv", |s, t| {
            let a = s.geometry.tri_attrs.first_mut()?;
            a.uvs[2].y = other(a.uvs[2].y, t);
            Some(Reach::Photons)
        }),
        ("geometry.sphere", |s, t| {
            let sp = s.geometry.spheres.first_mut()?;
            sp.radius = other(sp.radius, t);
            Some(Reach::Photons)
        }),
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 12, failure_persistence: None, ..ProptestConfig::default() })]

    /// Changing any one field (every mutation, on every scene that has the field, to a value
    /// drawn from `t`) changes the pixel key, and the photon key exactly when photon tracing
    /// reads the field; every mutation applies to at least one scene.
    #[test]
    fn changing_any_one_field_changes_the_key(t in 0.0f32..1.0) {
        for (name, mutate) in mutations() {
            let mut applied = false;
            for scene_name in SCENES {
                let mut s = scene(scene_name);
                let (photons, pixels) = (photon_key(&s), pixel_key(&s));
                let Some(reach) = mutate(&mut s, t) else {
                    continue; // this scene has no such field
                };
                applied = true;
                prop_assert_ne!(pixel_key(&s), pixels, "{} on {} left the pixel key", name, scene_name);
                match reach {
                    Reach::Photons => prop_assert_ne!(
                        photon_key(&s), photons, "{} on {} left the photon key", name, scene_name
                    ),
                    Reach::PixelsOnly => prop_assert_eq!(
                        photon_key(&s), photons, "{} on {} moved the photon key", name, scene_name
                    ),
                }
            }
            prop_assert!(applied, "no scene has {}", name);
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, failure_persistence: None, ..ProptestConfig::default() })]

    /// Two BSDFs built through every constructor key alike exactly when they are equal.
    #[test]
    fn bsdfs_key_alike_exactly_when_equal(
        a in bsdf_params(),
        b in bsdf_params(),
    ) {
        let (x, y) = (build(&a), build(&b));
        prop_assert_eq!(x == y, key(&x) == key(&y), "{:?} / {:?}", a, b);
        prop_assert_eq!(key(&x), key(&build(&a)));
    }
}

fn key(v: &impl KeyHash) -> u64 {
    let mut h = Fnv::new();
    v.key_hash(&mut h);
    h.finish()
}

/// The arguments of `Bsdf::new`, `with_microfacets` and `with_coat`, each from a small set so
/// that equal draws happen.
type BsdfParams = (
    [f32; 3],
    f32,
    f32,
    [Option<f32>; 3],
    f32,
    Option<(f32, f32)>,
    Option<u8>,
    Option<f32>,
);

fn bsdf_params() -> impl Strategy<Value = BsdfParams> {
    let small = prop::sample::select(vec![0.0f32, 0.25, 0.5, 1.0]);
    (
        [small.clone(), small.clone(), small.clone()],
        small.clone(),
        prop::sample::select(vec![1.0f32, 10.0]),
        [
            prop::option::of(small.clone()),
            prop::option::of(small.clone()),
            prop::option::of(small.clone()),
        ],
        prop::sample::select(vec![1.0f32, 1.5]),
        prop::option::of((
            prop::sample::select(vec![0.01f32, 0.2]),
            prop::sample::select(vec![0.01f32, 0.2]),
        )),
        prop::option::of(0u8..3),
        prop::option::of(prop::sample::select(vec![1.3f32, 1.6])),
    )
}

fn build(p: &BsdfParams) -> Bsdf {
    let (c, spec, shine, w, ior, rough, conductor, coat) = *p;
    let conductor = conductor.map(|k| match k {
        0 => ConductorFresnel::schlick(Vec3::splat(0.9)),
        1 => ConductorFresnel::f82_fit(Vec3::new(0.2, 0.9, 1.1), Vec3::splat(3.0)),
        _ => ConductorFresnel::schlick(Vec3::new(0.9, 0.6, 0.3)),
    });
    Bsdf::new(Vec3::from_array(c), Vec3::splat(spec), shine, w, ior)
        .with_microfacets(rough.map(|(x, y)| Ggx::new(x, y)), conductor)
        .with_coat(coat)
}

/// Hash written in a `.part` film's metadata.
fn part_hash(path: &Path) -> String {
    let bytes = std::fs::read(path).expect("part written");
    let text = String::from_utf8_lossy(&bytes);
    let i = text.find("hash=").expect("a hash line");
    text[i..].lines().next().unwrap_or("").to_string()
}

#[test]
fn output_path_and_thread_count_do_not_change_the_part_key() {
    let dir = tempfile::tempdir().expect("temp dir");
    let a = dir.path().join("a.part");
    let sub = dir.path().join("elsewhere");
    std::fs::create_dir_all(&sub).expect("mkdir");
    let b = sub.join("other-name.part");
    let common = [
        "render",
        "scenes/cornell.ron",
        "--width",
        "8",
        "--height",
        "6",
        "--spp",
        "1",
        "--quiet",
    ];
    for (threads, out) in [("1", &a), ("2", &b)] {
        let mut args = common.to_vec();
        args.extend(["--threads", threads, "-o", out.to_str().expect("utf-8")]);
        let o = caustic(&args);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    }
    assert_eq!(part_hash(&a), part_hash(&b));
    // ... while a setting that changes pixels does.
    let c = dir.path().join("c.part");
    let mut args = common.to_vec();
    args.extend(["--seed", "9", "-o", c.to_str().expect("utf-8")]);
    assert!(caustic(&args).status.success());
    assert_ne!(part_hash(&a), part_hash(&c));
}
