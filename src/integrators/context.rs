//! The one context argument of every estimator: where it draws random numbers, what it counts,
//! and who watches its paths. The watcher is a type parameter, so the normal render's no-op
//! [`NoTrace`] compiles away (monomorphised: no branch, no allocation per ray) while
//! `caustic debug-pixel` passes a [`TraceLog`] that records the ray tree.

use glam::Vec3;

use super::splat::FilmSplats;
use super::trace_log::{RayKind, ShadowRecord, TraceHit, TraceLog};
use super::{Counters, LightPath};
use crate::geometry::Ray;
use crate::render_scene::{Hit, RenderScene, SurfacePoint};
use crate::sampling::Sampler;

/// What an estimator tells about its paths as it traces them. Node ids are `Some` only for an
/// observer that records ([`PathObserver::ACTIVE`]); every method takes the id of the ray it is
/// about and does nothing for `None`.
pub trait PathObserver {
    /// True if the observer records anything: estimators build descriptions (text, blocker
    /// lookups) only when it is.
    const ACTIVE: bool;

    /// The id the next recorded ray will get (`None` when not recording).
    fn next_node(&self) -> Option<usize>;
    /// Records a ray cast at path depth `depth` for `kind`, carrying path weight `weight`, as a
    /// child of `parent`; returns its id.
    fn ray(
        &mut self,
        depth: u32,
        kind: RayKind,
        ray: &Ray,
        weight: Vec3,
        parent: Option<usize>,
    ) -> Option<usize>;
    /// Records the surface ray `node` hit (object and `material` names, the normal on the ray's
    /// side).
    fn hit(
        &mut self,
        node: Option<usize>,
        scene: &RenderScene,
        hit: &Hit,
        sp: &SurfacePoint,
        material: &str,
    );
    /// Records a hit described by the estimator itself.
    fn set_hit(&mut self, node: Option<usize>, hit: TraceHit);
    /// Records a shadow ray cast at `node`'s hit.
    fn shadow(&mut self, node: Option<usize>, record: ShadowRecord);
    /// Records why the path stopped at `node`, or what was estimated there.
    fn note(&mut self, node: Option<usize>, text: &str);
    /// Sets the radiance recorded at `node`.
    fn set_radiance(&mut self, node: Option<usize>, radiance: Vec3);
    /// Ends a path traced iteratively from `root`, whose nodes hold the radiance gathered
    /// before each: each becomes what its ray brought back, `(total − before) / weight`.
    fn finish_path(&mut self, root: Option<usize>, total: Vec3);
    /// Ends a tree from `root` whose nodes hold the weighted radiance gathered at each hit
    /// ([`TraceLog::finish_tree`]).
    fn finish_tree(&mut self, root: Option<usize>);
}

/// The observer of normal renders: records nothing, costs nothing.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct NoTrace;

impl PathObserver for NoTrace {
    const ACTIVE: bool = false;

    #[inline(always)]
    fn next_node(&self) -> Option<usize> {
        None
    }
    #[inline(always)]
    fn ray(&mut self, _: u32, _: RayKind, _: &Ray, _: Vec3, _: Option<usize>) -> Option<usize> {
        None
    }
    #[inline(always)]
    fn hit(&mut self, _: Option<usize>, _: &RenderScene, _: &Hit, _: &SurfacePoint, _: &str) {}
    #[inline(always)]
    fn set_hit(&mut self, _: Option<usize>, _: TraceHit) {}
    #[inline(always)]
    fn shadow(&mut self, _: Option<usize>, _: ShadowRecord) {}
    #[inline(always)]
    fn note(&mut self, _: Option<usize>, _: &str) {}
    #[inline(always)]
    fn set_radiance(&mut self, _: Option<usize>, _: Vec3) {}
    #[inline(always)]
    fn finish_path(&mut self, _: Option<usize>, _: Vec3) {}
    #[inline(always)]
    fn finish_tree(&mut self, _: Option<usize>) {}
}

impl PathObserver for TraceLog {
    const ACTIVE: bool = true;

    fn next_node(&self) -> Option<usize> {
        Some(self.nodes.len())
    }
    fn ray(
        &mut self,
        depth: u32,
        kind: RayKind,
        ray: &Ray,
        weight: Vec3,
        parent: Option<usize>,
    ) -> Option<usize> {
        Some(self.push(depth, kind, ray, weight, parent))
    }
    fn hit(
        &mut self,
        node: Option<usize>,
        scene: &RenderScene,
        hit: &Hit,
        sp: &SurfacePoint,
        material: &str,
    ) {
        self.record_hit(node, scene, hit, sp, material);
    }
    fn set_hit(&mut self, node: Option<usize>, hit: TraceHit) {
        if let Some(me) = node {
            self.nodes[me].hit = Some(hit);
        }
    }
    fn shadow(&mut self, node: Option<usize>, record: ShadowRecord) {
        if let Some(me) = node {
            self.nodes[me].shadows.push(record);
        }
    }
    fn note(&mut self, node: Option<usize>, text: &str) {
        TraceLog::note(Some(self), node, text);
    }
    fn set_radiance(&mut self, node: Option<usize>, radiance: Vec3) {
        if let Some(me) = node {
            self.nodes[me].radiance = radiance;
        }
    }
    fn finish_path(&mut self, root: Option<usize>, total: Vec3) {
        if let Some(root) = root {
            for n in &mut self.nodes[root..] {
                let gathered = total - n.radiance;
                n.radiance =
                    Vec3::select(n.weight.cmpgt(Vec3::ZERO), gathered / n.weight, Vec3::ZERO);
            }
        }
    }
    fn finish_tree(&mut self, root: Option<usize>) {
        if let Some(root) = root {
            TraceLog::finish_tree(self, root);
        }
    }
}

/// The context an estimator runs in for one camera sample: the sampler (already started on
/// this pixel sample), the worker's ray counters, the path observer, and the job's splat
/// buffers for contributions to other pixels than the one sampled.
#[derive(Debug)]
pub struct Context<'c, O: PathObserver> {
    /// Where random numbers come from.
    pub sampler: &'c mut Sampler,
    /// Rays and estimates counted.
    pub counters: &'c mut Counters,
    /// Who watches the paths ([`NoTrace`] in renders, a [`TraceLog`] in `debug-pixel`).
    pub observer: &'c mut O,
    /// Where contributions to other pixels go ([`Context::splat`]): `Some` in a render job of
    /// an estimator that declares [`Estimator::splats`](super::Estimator::splats).
    pub splats: Option<&'c FilmSplats>,
}

impl<'c, O: PathObserver> Context<'c, O> {
    /// A context over the given parts.
    #[inline]
    pub fn new(sampler: &'c mut Sampler, counters: &'c mut Counters, observer: &'c mut O) -> Self {
        Self {
            sampler,
            counters,
            observer,
            splats: None,
        }
    }

    /// The context with the job's splat buffers (`None`: splats are not kept).
    #[inline]
    #[must_use]
    pub fn with_splats(mut self, splats: Option<&'c FilmSplats>) -> Self {
        self.splats = splats;
        self
    }

    /// Adds `value` (W·m⁻²·sr⁻¹ per channel) of light-path kind `kind` to image pixel `(x, y)`
    /// as a contribution of this camera sample — light tracing's camera connections, BDPT's
    /// t = 1 strategy (Veach 1997, §10.2). The pixel's value becomes (Σ samples + Σ splats) /
    /// spp: the contract of [`super::splat`]. Without splat buffers (an estimator that does not
    /// declare [`Estimator::splats`](super::Estimator::splats), or `debug-pixel`) the value is
    /// not kept.
    #[inline]
    pub fn splat(&self, x: u32, y: u32, kind: LightPath, value: Vec3) {
        if let Some(s) = self.splats {
            s.add(x, y, kind, value);
        }
    }
}
