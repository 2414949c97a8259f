//! The photon-map cache (`--photon-cache DIR`): the built maps saved to disk and reused by the
//! next render of the same scene when only the camera, the image size or the samples change.
//!
//! **Key.** [`cache_key`], the scene's photon key
//! ([`crate::render_scene::hash::photon_key`]: a 64-bit FNV-1a hash of everything photon
//! tracing reads, shared with the `.part` films' settings hash). Settings that only the estimate
//! reads (`gather`, `caustic_gather`, `max_radius`, `caustic_cone`, `final_gather`) are not in
//! the key: the loaded photons are wrapped with the current ones. The key names the file
//! (`photons-<key>.bin`), so a scene change looks up another file: stale files are never read.
//! A change to the photon tracer itself must bump [`KEY_VERSION`].
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

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

use glam::Vec3;

use super::estimate::{Kernel, PhotonMap};
use super::maps::{
    PhotonMaps, PhotonSummary, auto_radius, build_maps_cancellable, diffuse_area,
    precompute_irradiance, use_photon_discs,
};
use super::trace::{MapKind, TraceCounts};
use super::walls::Walls;
use crate::binfile::{AtomicWrite, Reader, Truncated, fnv1a};
use crate::render_scene::RenderScene;
pub use crate::render_scene::hash::{PHOTON_KEY_VERSION as KEY_VERSION, photon_key as cache_key};
use crate::spatial::{BuildOptions, KdTree, KdTreeError, Photon};

/// File signature and format version of a cache file.
pub const MAGIC: &[u8; 16] = b"caustic-photons1";

/// How cache files are written: hidden `.photons-*.tmp` temporary files, owner-only.
const CACHE_FILES: AtomicWrite = AtomicWrite {
    temp_prefix: ".photons-",
    owner_only: true,
};

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
        reason: DecodeError,
    },
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
            // The photon integrator, the cache's only user, stores no volume photons.
            volume_stored: _,
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
    let sum = fnv1a(&out);
    put_u64(&mut out, sum);
    out
}

/// Saves `maps` under `key` as the cache file `path` (temporary file + rename).
///
/// # Errors
/// [`CacheError::Io`] when the file cannot be written.
pub fn save(maps: &PhotonMaps, path: &Path, key: u64) -> Result<(), CacheError> {
    CACHE_FILES
        .write(path, &encode(maps, key))
        .map_err(|source| CacheError::Io {
            path: path.to_path_buf(),
            source,
        })
}

/// Why the bytes of a cache file are not a valid cache of the key asked for.
#[derive(Debug, thiserror::Error)]
pub enum DecodeError {
    /// The bytes do not start with [`MAGIC`] (or are shorter than a header).
    #[error("it does not start with the photon cache signature")]
    Signature,
    /// The trailing checksum is not the hash of the rest.
    #[error("the checksum does not match (truncated or corrupt)")]
    Checksum,
    /// A field runs past the end.
    #[error(transparent)]
    Truncated(#[from] Truncated),
    /// The file holds the maps of another scene.
    #[error("it holds the maps of key {stored:016x}, not {key:016x}")]
    OtherKey {
        /// The key in the file.
        stored: u64,
        /// The key asked for.
        key: u64,
    },
    /// The number of lights does not fit this machine's `usize`.
    #[error("{0}")]
    Targets(std::num::TryFromIntError),
    /// A skip reason's bytes are not UTF-8.
    #[error("a skip reason is not UTF-8")]
    NotUtf8,
    /// A count of per-light records larger than the bytes left could hold.
    #[error("{0} lights' counts cannot fit in the file")]
    Counts(u64),
    /// A photon count larger than the bytes left could hold.
    #[error("{0} photons cannot fit in the file")]
    Photons(u64),
    /// Bytes left over after the last map.
    #[error("{0} unexpected bytes at the end")]
    Trailing(usize),
    /// The stored photons are not in kd-tree order.
    #[error("{0}")]
    Tree(#[from] KdTreeError),
}

/// The cache file's fields over the little-endian [`Reader`].
struct CacheReader<'a>(Reader<'a>);

impl CacheReader<'_> {
    fn vec3(&mut self) -> Result<Vec3, Truncated> {
        Ok(Vec3::new(self.0.f32()?, self.0.f32()?, self.0.f32()?))
    }

    fn text(&mut self) -> Result<Option<String>, DecodeError> {
        let n = self.0.u32()?;
        if n == u32::MAX {
            return Ok(None);
        }
        let b = self.0.take(n as usize)?;
        String::from_utf8(b.to_vec())
            .map(Some)
            .map_err(|_| DecodeError::NotUtf8)
    }

    fn counts(&mut self) -> Result<Vec<TraceCounts>, DecodeError> {
        let n = self.0.u64()?;
        if n > self.0.rest().len() as u64 / 56 {
            return Err(DecodeError::Counts(n));
        }
        (0..n)
            .map(|_| {
                let r = &mut self.0;
                let [emitted, reached_specular, stored, lost_at_depth] =
                    [r.u64()?, r.u64()?, r.u64()?, r.u64()?];
                Ok(TraceCounts {
                    emitted,
                    reached_specular,
                    stored,
                    stored_flux: self.vec3()?,
                    lost_at_depth,
                    lost_flux: self.vec3()?,
                    volume_stored: 0,
                })
            })
            .collect()
    }

    fn photons(&mut self) -> Result<Option<Vec<Photon>>, DecodeError> {
        let n = self.0.u64()?;
        if n == u64::MAX {
            return Ok(None);
        }
        if n > self.0.rest().len() as u64 / 24 {
            return Err(DecodeError::Photons(n));
        }
        let b = self.0.take(n as usize * 24)?;
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
/// `scene`'s current gather settings.
///
/// # Errors
/// A [`DecodeError`] saying what is wrong when the bytes are truncated, fail the checksum, carry
/// another key, or hold photons that are not a kd-tree.
pub fn decode(scene: &RenderScene, bytes: &[u8], key: u64) -> Result<PhotonMaps, DecodeError> {
    let t0 = Instant::now();
    if bytes.len() < MAGIC.len() + 16 || &bytes[..MAGIC.len()] != MAGIC {
        return Err(DecodeError::Signature);
    }
    let (body, sum) = bytes.split_at(bytes.len() - 8);
    if fnv1a(body).to_le_bytes() != sum {
        return Err(DecodeError::Checksum);
    }
    let mut r = CacheReader(Reader::new(&body[MAGIC.len()..]));
    let stored_key = r.0.u64()?;
    if stored_key != key {
        return Err(DecodeError::OtherKey {
            stored: stored_key,
            key,
        });
    }
    let mut summary = PhotonSummary {
        targets: usize::try_from(r.0.u64()?).map_err(DecodeError::Targets)?,
        caustic_skipped: r.text()?,
        global_skipped: r.text()?,
        caustic: r.counts()?,
        global: r.counts()?,
        ..PhotonSummary::default()
    };
    let caustic = r.photons()?;
    let global = r.photons()?;
    if !r.0.rest().is_empty() {
        return Err(DecodeError::Trailing(r.0.rest().len()));
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
     -> Result<Option<PhotonMap>, DecodeError> {
        let Some(photons) = photons else {
            return Ok(None);
        };
        let r = p
            .max_radius
            .unwrap_or_else(|| auto_radius(area, photons.len() as u64, k, kind));
        let tree = KdTree::from_tree_order(photons, BuildOptions::default())?;
        memory += tree.memory_bytes();
        *radius = r;
        let mut map = PhotonMap::new(tree, k as usize, r, kernel);
        map.mark_walls(Walls::of(scene, None));
        Ok(Some(map))
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
    let (mut caustic, mut global) = (caustic, global);
    use_photon_discs(scene, &mut caustic, &mut global, &mut summary);
    summary.build_time = t0.elapsed();
    let irradiance = precompute_irradiance(scene, &caustic, &global, &mut summary, None);
    Ok(PhotonMaps {
        caustic,
        global,
        irradiance,
        volume_photons: Vec::new(),
        volume: None,
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
