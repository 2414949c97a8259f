//! The photon-map cache (`--photon-cache DIR`): the built maps saved to disk and reused by the
//! next render of the same scene when only the camera, the image size or the samples change.
//!
//! **Key.** A 64-bit FNV-1a hash of everything photon tracing reads: the primitives (triangles
//! with their normals, uvs and objects; spheres; ellipsoids), which material and light each
//! object has, the materials (BSDF values, texture and bump references), the textures (their
//! parameters, and the level-0 texels of image textures: photons look textures up with a zero
//! footprint), the lights, the photon counts and bounce limits, the seed, the sampler and the
//! texture filter, plus [`KEY_VERSION`] and the crate version. Settings that only the estimate
//! reads (`gather`, `caustic_gather`, `max_radius`, `caustic_cone`, `final_gather`) are not in
//! the key: the loaded photons are wrapped with the current ones. The key names the file
//! (`photons-<key>.bin`), so a scene change looks up another file: stale files are never read.
//! The struct fields are destructured exhaustively, so a field added later fails to compile
//! here until it is put in the key or declared irrelevant. A change to the photon tracer itself
//! must bump [`KEY_VERSION`].
//!
//! **File** (little-endian): [`MAGIC`], the key, the summary's per-light counts and skip reasons,
//! each map's photons as packed words in kd-tree order, and an FNV-1a checksum of all that (as
//! the `.part` films). A file that is truncated, corrupt, or of another key or format is reported
//! and rebuilt, never trusted; files are written to a temporary file and renamed, so two renders
//! saving the same key at once each leave a whole file.
//!
//! **Load.** The trees are rebuilt with [`KdTree::from_tree_order`], which recomputes the stems
//! without moving photons, so slots, ties and sums are those of a fresh build: a hit renders the
//! same bytes. (For 1M photons this is several times faster than [`KdTree::build`]; figures in
//! `docs/photon_map.md`.)

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use glam::Vec3;

use super::estimate::{Kernel, PhotonMap};
use super::maps::{
    PhotonMaps, PhotonSummary, auto_radius, build_maps_cancellable, diffuse_area,
    precompute_irradiance,
};
use super::trace::{MapKind, TraceCounts};
use crate::photon::{BuildOptions, KdTree, Photon};
use crate::render_scene::geometry::{EllipsoidPrim, SpherePrim, TriAttrs};
use crate::render_scene::{Geometry, ObjectInfo, PhotonParams, RenderParams, RenderScene, Texture};

/// File signature and format version of a cache file.
pub const MAGIC: &[u8; 16] = b"caustic-photons1";

/// Version of what the key covers and of the photon tracer: bump it when photon tracing changes
/// so that old cache files miss.
pub const KEY_VERSION: u32 = 1;

/// Why a cache file could not be read.
#[derive(Debug, thiserror::Error)]
pub enum CacheError {
    /// Reading or writing failed.
    #[error("`{path}`: {source}")]
    Io {
        /// The cache file.
        path: PathBuf,
        /// The OS error.
        source: std::io::Error,
    },
    /// Truncated, corrupt, or not a photon cache of this key.
    #[error("`{path}` is not a valid photon cache file for this scene: {reason}")]
    Invalid {
        /// The cache file.
        path: PathBuf,
        /// What is wrong.
        reason: String,
    },
}

/// FNV-1a, 64 bits, fed incrementally (keys and checksums; detects accidents, not adversaries).
#[derive(Debug, Clone, Copy)]
struct Fnv(u64);

impl Fnv {
    const OFFSET: u64 = 0xcbf2_9ce4_8422_2325;
    const PRIME: u64 = 0x0000_0100_0000_01b3;

    fn new() -> Self {
        Self(Self::OFFSET)
    }

    fn bytes(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 ^= u64::from(b);
            self.0 = self.0.wrapping_mul(Self::PRIME);
        }
    }

    fn u32(&mut self, v: u32) {
        self.bytes(&v.to_le_bytes());
    }

    fn u64(&mut self, v: u64) {
        self.bytes(&v.to_le_bytes());
    }

    fn f32(&mut self, v: f32) {
        self.u32(v.to_bits());
    }

    fn vec3(&mut self, v: Vec3) {
        for c in v.to_array() {
            self.f32(c);
        }
    }

    /// Hashes a tag then `v`'s `Debug` text: every field, floats printed so that they read back
    /// exactly (distinct values print differently), without building the string.
    fn debug(&mut self, tag: &str, v: &impl std::fmt::Debug) {
        self.bytes(tag.as_bytes());
        // Writing into the hasher cannot fail.
        let _ = write!(self, "{v:?};");
    }
}

impl std::fmt::Write for Fnv {
    fn write_str(&mut self, s: &str) -> std::fmt::Result {
        self.bytes(s.as_bytes());
        Ok(())
    }
}

/// The cache key of `scene`'s photon maps (module docs for what it covers).
#[must_use]
pub fn cache_key(scene: &RenderScene) -> u64 {
    let RenderScene {
        params,
        camera: _,
        materials,
        textures,
        material_names: _,
        lights,
        objects,
        geometry,
    } = scene;
    let mut h = Fnv::new();
    h.bytes(MAGIC);
    h.u32(KEY_VERSION);
    h.bytes(env!("CARGO_PKG_VERSION").as_bytes());
    hash_params(&mut h, params);
    h.u64(objects.len() as u64);
    for o in objects {
        let ObjectInfo {
            name: _,
            material,
            light,
        } = o;
        h.debug("o", &(material, light));
    }
    h.debug("materials", materials);
    h.u64(textures.len() as u64);
    for t in textures {
        hash_texture(&mut h, t);
    }
    h.debug("lights", lights);
    hash_geometry(&mut h, geometry);
    h.0
}

fn hash_params(h: &mut Fnv, params: &RenderParams) {
    let RenderParams {
        width: _,
        height: _,
        samples_per_pixel: _,
        max_depth: _,
        min_contribution: _,
        light_samples: _,
        seed,
        background: _,
        exposure: _,
        integrator: _,
        sampler,
        diffuse_depth: _,
        texture_filter,
        photons,
    } = params;
    let PhotonParams {
        global,
        caustic,
        caustic_per_light,
        gather: _,
        caustic_gather: _,
        max_radius: _,
        alpha: _,
        caustic_cone: _,
        min_bounces,
        final_gather: _,
        max_bounces,
    } = photons;
    h.debug(
        "params",
        &(
            seed,
            sampler,
            texture_filter,
            global,
            caustic,
            caustic_per_light,
            min_bounces,
            max_bounces,
        ),
    );
}

fn hash_texture(h: &mut Fnv, t: &Texture) {
    match t {
        Texture::Bitmap(b) => {
            h.debug("bitmap", &b.tile);
            let (w, hh) = (b.mip.width(), b.mip.height());
            h.u32(w);
            h.u32(hh);
            for y in 0..i64::from(hh) {
                for x in 0..i64::from(w) {
                    h.vec3(b.mip.texel(0, x, y));
                }
            }
        }
        Texture::HeightMap(m) => {
            h.debug("heightmap", &(m.depth, m.tile));
            let (w, hh) = (m.mip.width(), m.mip.height());
            h.u32(w);
            h.u32(hh);
            for y in 0..i64::from(hh) {
                for x in 0..i64::from(w) {
                    h.f32(m.mip.texel(0, x, y));
                }
            }
        }
        other => h.debug("texture", other),
    }
}

fn hash_geometry(h: &mut Fnv, g: &Geometry) {
    let Geometry {
        bvh: _,
        slots: _,
        tri_packs: _,
        has_quadrics: _,
        quadric_packs: _,
        triangles,
        tri_attrs,
        spheres,
        ellipsoids,
    } = g;
    h.bytes(b"triangles");
    h.u64(triangles.len() as u64);
    for (t, a) in triangles.iter().zip(tri_attrs) {
        for v in t {
            h.vec3(*v);
        }
        let TriAttrs {
            object,
            normals,
            uvs,
        } = a;
        h.u32(*object);
        match normals {
            Some(n) => {
                h.u32(1);
                for v in n {
                    h.vec3(*v);
                }
            }
            None => h.u32(0),
        }
        for uv in uvs {
            h.f32(uv.x);
            h.f32(uv.y);
        }
    }
    h.bytes(b"spheres");
    h.u64(spheres.len() as u64);
    for s in spheres {
        let SpherePrim {
            center,
            radius,
            object,
        } = s;
        h.vec3(*center);
        h.f32(*radius);
        h.u32(*object);
    }
    h.u64(ellipsoids.len() as u64);
    for e in ellipsoids {
        let EllipsoidPrim {
            object_from_world,
            world_from_object,
            normal_to_world,
            object,
        } = e;
        h.debug(
            "e",
            &(
                object_from_world,
                world_from_object,
                normal_to_world,
                object,
            ),
        );
    }
}

/// The cache file of key `key` in `dir`.
#[must_use]
pub fn cache_file(dir: &Path, key: u64) -> PathBuf {
    dir.join(format!("photons-{key:016x}.bin"))
}

/// The maps `scene` asks for: read from `cache` (a folder) when it holds them for this scene,
/// else built with [`build_maps_cancellable`] and saved there. Never fails: a cache that cannot be read is
/// rebuilt, one that cannot be written is skipped; `summary.cache` says which happened. A
/// raised `cancel` stops the build ([`PhotonSummary::cancelled`]) and nothing is saved.
#[must_use]
pub fn build_or_load(
    scene: &RenderScene,
    cache: Option<&Path>,
    cancel: Option<Arc<AtomicBool>>,
) -> PhotonMaps {
    let Some(dir) = cache else {
        return build_maps_cancellable(scene, cancel);
    };
    let key = cache_key(scene);
    let path = cache_file(dir, key);
    let failed = if path.exists() {
        match load(scene, &path, key) {
            Ok(mut maps) => {
                maps.summary.cache = Some(format!("photon cache: hit ({})", path.display()));
                return maps;
            }
            Err(e) => Some(e),
        }
    } else {
        None
    };
    let mut maps = build_maps_cancellable(scene, cancel);
    if maps.summary.cancelled {
        return maps;
    }
    let saved = std::fs::create_dir_all(dir)
        .map_err(|source| CacheError::Io {
            path: dir.to_path_buf(),
            source,
        })
        .and_then(|()| save(&maps, &path, key));
    let line = match (failed, saved) {
        (None, Ok(())) => format!("photon cache: miss: built and saved ({})", path.display()),
        (None, Err(e)) => format!("warning: photon cache: miss: built but not saved: {e}"),
        (Some(bad), Ok(())) => {
            format!("warning: photon cache: corrupt: rebuilt and saved ({bad})")
        }
        (Some(bad), Err(e)) => {
            format!("warning: photon cache: corrupt: rebuilt but not saved ({bad}; {e})")
        }
    };
    maps.summary.cache = Some(line);
    maps
}

fn put_u32(out: &mut Vec<u8>, v: u32) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_u64(out: &mut Vec<u8>, v: u64) {
    out.extend_from_slice(&v.to_le_bytes());
}

fn put_vec3(out: &mut Vec<u8>, v: Vec3) {
    for c in v.to_array() {
        put_u32(out, c.to_bits());
    }
}

fn put_text(out: &mut Vec<u8>, s: Option<&str>) {
    match s {
        None => put_u32(out, u32::MAX),
        Some(s) => {
            put_u32(out, s.len() as u32);
            out.extend_from_slice(s.as_bytes());
        }
    }
}

fn put_counts(out: &mut Vec<u8>, per_light: &[TraceCounts]) {
    put_u64(out, per_light.len() as u64);
    for c in per_light {
        let TraceCounts {
            emitted,
            reached_specular,
            stored,
            stored_flux,
            lost_at_depth,
            lost_flux,
        } = *c;
        for v in [emitted, reached_specular, stored, lost_at_depth] {
            put_u64(out, v);
        }
        put_vec3(out, stored_flux);
        put_vec3(out, lost_flux);
    }
}

fn put_map(out: &mut Vec<u8>, map: Option<&PhotonMap>) {
    match map {
        None => put_u64(out, u64::MAX),
        Some(m) => {
            put_u64(out, m.len() as u64);
            for p in m.photons() {
                for w in p.to_words() {
                    put_u32(out, w);
                }
            }
        }
    }
}

/// The bytes of the cache file of `maps` under `key`.
#[must_use]
pub fn encode(maps: &PhotonMaps, key: u64) -> Vec<u8> {
    let s = &maps.summary;
    let photons = maps.caustic.as_ref().map_or(0, PhotonMap::len)
        + maps.global.as_ref().map_or(0, PhotonMap::len);
    let mut out = Vec::with_capacity(256 + 24 * photons);
    out.extend_from_slice(MAGIC);
    put_u64(&mut out, key);
    put_u64(&mut out, s.targets as u64);
    put_text(&mut out, s.caustic_skipped.as_deref());
    put_text(&mut out, s.global_skipped.as_deref());
    put_counts(&mut out, &s.caustic);
    put_counts(&mut out, &s.global);
    put_map(&mut out, maps.caustic.as_ref());
    put_map(&mut out, maps.global.as_ref());
    let mut h = Fnv::new();
    h.bytes(&out);
    put_u64(&mut out, h.0);
    out
}

/// Saves `maps` under `key` as the cache file `path` (temporary file + rename).
///
/// # Errors
/// [`CacheError::Io`] when the file cannot be written.
pub fn save(maps: &PhotonMaps, path: &Path, key: u64) -> Result<(), CacheError> {
    use std::io::Write as _;
    let bytes = encode(maps, key);
    let io = |source| CacheError::Io {
        path: path.to_path_buf(),
        source,
    };
    let dir = path.parent().unwrap_or(Path::new("."));
    let mut tmp = tempfile::Builder::new()
        .prefix(".photons-")
        .suffix(".tmp")
        .tempfile_in(dir)
        .map_err(io)?;
    tmp.write_all(&bytes).map_err(io)?;
    tmp.as_file().sync_all().map_err(io)?;
    tmp.persist(path).map_err(|e| io(e.error))?;
    Ok(())
}

/// A little-endian reader over a cache file's body that reports truncation.
struct Reader<'a> {
    bytes: &'a [u8],
}

impl Reader<'_> {
    fn take(&mut self, n: usize) -> Result<&[u8], String> {
        if self.bytes.len() < n {
            return Err("the file is truncated".into());
        }
        let (head, rest) = self.bytes.split_at(n);
        self.bytes = rest;
        Ok(head)
    }

    fn u32(&mut self) -> Result<u32, String> {
        let b = self.take(4)?;
        Ok(u32::from_le_bytes([b[0], b[1], b[2], b[3]]))
    }

    fn u64(&mut self) -> Result<u64, String> {
        Ok(u64::from(self.u32()?) | (u64::from(self.u32()?) << 32))
    }

    fn vec3(&mut self) -> Result<Vec3, String> {
        Ok(Vec3::new(
            f32::from_bits(self.u32()?),
            f32::from_bits(self.u32()?),
            f32::from_bits(self.u32()?),
        ))
    }

    fn text(&mut self) -> Result<Option<String>, String> {
        let n = self.u32()?;
        if n == u32::MAX {
            return Ok(None);
        }
        let b = self.take(n as usize)?;
        String::from_utf8(b.to_vec())
            .map(Some)
            .map_err(|_| "a skip reason is not UTF-8".into())
    }

    fn counts(&mut self) -> Result<Vec<TraceCounts>, String> {
        let n = self.u64()?;
        if n > self.bytes.len() as u64 / 56 {
            return Err(format!("{n} lights' counts cannot fit in the file"));
        }
        (0..n)
            .map(|_| {
                let [emitted, reached_specular, stored, lost_at_depth] =
                    [self.u64()?, self.u64()?, self.u64()?, self.u64()?];
                Ok(TraceCounts {
                    emitted,
                    reached_specular,
                    stored,
                    stored_flux: self.vec3()?,
                    lost_at_depth,
                    lost_flux: self.vec3()?,
                })
            })
            .collect()
    }

    fn photons(&mut self) -> Result<Option<Vec<Photon>>, String> {
        let n = self.u64()?;
        if n == u64::MAX {
            return Ok(None);
        }
        if n > self.bytes.len() as u64 / 24 {
            return Err(format!("{n} photons cannot fit in the file"));
        }
        let b = self.take(n as usize * 24)?;
        Ok(Some(
            b.chunks_exact(24)
                .map(|c| {
                    let w = |i: usize| u32::from_le_bytes([c[i], c[i + 1], c[i + 2], c[i + 3]]);
                    Photon::from_words([w(0), w(4), w(8), w(12), w(16), w(20)])
                })
                .collect(),
        ))
    }
}

/// The maps stored in `bytes` (a file made by [`encode`] with `key`), wrapped for estimates with
/// `scene`'s current gather settings. `Err` says what is wrong.
///
/// # Errors
/// A message when the bytes are truncated, fail the checksum, carry another key, or hold
/// photons that are not a kd-tree.
pub fn decode(scene: &RenderScene, bytes: &[u8], key: u64) -> Result<PhotonMaps, String> {
    let t0 = Instant::now();
    if bytes.len() < MAGIC.len() + 16 || &bytes[..MAGIC.len()] != MAGIC {
        return Err("it does not start with the photon cache signature".into());
    }
    let (body, sum) = bytes.split_at(bytes.len() - 8);
    let mut h = Fnv::new();
    h.bytes(body);
    if h.0.to_le_bytes() != sum {
        return Err("the checksum does not match (truncated or corrupt)".into());
    }
    let mut r = Reader {
        bytes: &body[MAGIC.len()..],
    };
    let stored_key = r.u64()?;
    if stored_key != key {
        return Err(format!(
            "it holds the maps of key {stored_key:016x}, not {key:016x}"
        ));
    }
    let mut summary = PhotonSummary {
        targets: usize::try_from(r.u64()?).map_err(|e| e.to_string())?,
        caustic_skipped: r.text()?,
        global_skipped: r.text()?,
        caustic: r.counts()?,
        global: r.counts()?,
        ..PhotonSummary::default()
    };
    let caustic = r.photons()?;
    let global = r.photons()?;
    if !r.bytes.is_empty() {
        return Err(format!("{} unexpected bytes at the end", r.bytes.len()));
    }
    let p = &scene.params.photons;
    summary.auto_radius = p.max_radius.is_none();
    let area = diffuse_area(scene);
    let mut memory = 0;
    let mut wrap = |photons: Option<Vec<Photon>>,
                    kind: MapKind,
                    k: u32,
                    kernel: Kernel,
                    radius: &mut f32|
     -> Result<Option<PhotonMap>, String> {
        let Some(photons) = photons else {
            return Ok(None);
        };
        let r = p
            .max_radius
            .unwrap_or_else(|| auto_radius(area, photons.len() as u64, k, kind));
        let tree =
            KdTree::from_tree_order(photons, BuildOptions::default()).map_err(|e| e.to_string())?;
        memory += tree.memory_bytes();
        *radius = r;
        Ok(Some(PhotonMap::new(tree, k as usize, r, kernel)))
    };
    let caustic_kernel = match p.caustic_cone {
        Some(k) => Kernel::Cone(k),
        None => Kernel::Box,
    };
    let caustic = wrap(
        caustic,
        MapKind::Caustic,
        p.caustic_gather,
        caustic_kernel,
        &mut summary.caustic_radius,
    )?;
    let global = wrap(
        global,
        MapKind::Global,
        p.gather,
        Kernel::Box,
        &mut summary.global_radius,
    )?;
    summary.memory = memory;
    summary.trace_time = Duration::ZERO;
    summary.build_time = t0.elapsed();
    let irradiance = precompute_irradiance(scene, &caustic, &global, &mut summary, None);
    Ok(PhotonMaps {
        caustic,
        global,
        irradiance,
        summary,
    })
}

/// Reads the cache file `path` for `scene`, whose [`cache_key`] is `key`.
///
/// # Errors
/// [`CacheError::Io`] when it cannot be read, [`CacheError::Invalid`] when it is not a valid
/// cache of `key`.
pub fn load(scene: &RenderScene, path: &Path, key: u64) -> Result<PhotonMaps, CacheError> {
    let bytes = std::fs::read(path).map_err(|source| CacheError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    decode(scene, &bytes, key).map_err(|reason| CacheError::Invalid {
        path: path.to_path_buf(),
        reason,
    })
}
