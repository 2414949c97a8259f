//! The ray tree of one pixel sample, recorded by `caustic debug-pixel` (the report's `debug_render`).

use glam::Vec3;

use crate::geometry::Ray;
use crate::render_scene::{Hit, RenderScene, SurfacePoint};

/// Why a ray was cast.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RayKind {
    /// From the camera.
    Camera,
    /// Mirror direction (mirror part or Fresnel reflection).
    Reflect,
    /// Refracted through a dielectric.
    Refract,
    /// Sampled from the diffuse or glossy part (path tracing).
    Scatter,
}

/// What a traced ray hit.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceHit {
    /// Distance.
    pub t: f32,
    /// Hit point.
    pub point: Vec3,
    /// Shading normal, facing the ray.
    pub normal: Vec3,
    /// Object name.
    pub object: String,
    /// Material name, or `light` for an emitter.
    pub material: String,
    /// True when the ray arrived from outside the object.
    pub entering: bool,
}

/// One shadow ray towards a light.
#[derive(Debug, Clone, PartialEq)]
pub struct ShadowRecord {
    /// Light index.
    pub light: usize,
    /// Direction towards the light.
    pub dir: Vec3,
    /// Whether something blocked it.
    pub occluded: bool,
    /// Radiance it added (zero when occluded).
    pub contribution: Vec3,
    /// What blocked it (object name and distance), when occluded.
    pub blocker: Option<(String, f32)>,
}

/// One ray of the tree.
#[derive(Debug, Clone, PartialEq)]
pub struct TraceNode {
    /// Recursion depth (camera ray = 0).
    pub depth: u32,
    /// Why it was cast.
    pub kind: RayKind,
    /// Origin.
    pub origin: Vec3,
    /// Direction.
    pub dir: Vec3,
    /// Product of lobe weights from the camera to this ray.
    pub weight: Vec3,
    /// The hit, or `None` for the background.
    pub hit: Option<TraceHit>,
    /// Shadow rays cast at the hit.
    pub shadows: Vec<ShadowRecord>,
    /// Radiance this ray returned.
    pub radiance: Vec3,
    /// Rays spawned at the hit.
    pub children: Vec<usize>,
    /// Why recursion stopped here, if it did.
    pub note: Option<String>,
}

/// The whole tree; node 0 is the camera ray.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TraceLog {
    /// Nodes in creation order.
    pub nodes: Vec<TraceNode>,
}

fn v3(v: Vec3) -> String {
    format!("({:.4}, {:.4}, {:.4})", v.x, v.y, v.z)
}

impl TraceLog {
    /// Appends the node of a ray cast at path depth `depth` for `kind`, carrying path weight
    /// `weight`, as a child of `parent`; returns its index.
    pub fn push(
        &mut self,
        depth: u32,
        kind: RayKind,
        ray: &Ray,
        weight: Vec3,
        parent: Option<usize>,
    ) -> usize {
        let id = self.nodes.len();
        self.nodes.push(TraceNode {
            depth,
            kind,
            origin: ray.origin,
            dir: ray.dir,
            weight,
            hit: None,
            shadows: Vec::new(),
            radiance: Vec3::ZERO,
            children: Vec::new(),
            note: None,
        });
        if let Some(p) = parent {
            self.nodes[p].children.push(id);
        }
        id
    }

    /// Records the surface `sp` that ray `node` hit (object and `material` names, the normal on
    /// the ray's side).
    pub fn record_hit(
        &mut self,
        node: Option<usize>,
        scene: &RenderScene,
        hit: &Hit,
        sp: &SurfacePoint,
        material: &str,
    ) {
        if let Some(me) = node {
            let wo = -self.nodes[me].dir;
            let entering = wo.dot(sp.ng) > 0.0;
            self.nodes[me].hit = Some(TraceHit {
                t: hit.t,
                point: sp.p,
                normal: if entering { sp.ns } else { -sp.ns },
                object: scene.objects[sp.object as usize].name.clone(),
                material: material.to_string(),
                entering,
            });
        }
    }

    /// For a tree whose nodes from `root` on hold the weighted radiance gathered *at* each ray's
    /// hit (path weight × what that vertex added), turns each into the radiance the ray
    /// brought back: its own plus its descendants', divided by its path weight.
    pub fn finish_tree(&mut self, root: usize) {
        for i in (root + 1..self.nodes.len()).rev() {
            let c = self.nodes[i].radiance;
            if let Some(p) = (root..i)
                .rev()
                .find(|&p| self.nodes[p].children.contains(&i))
            {
                self.nodes[p].radiance += c;
            }
        }
        for n in &mut self.nodes[root..] {
            n.radiance = Vec3::select(
                n.weight.cmpgt(Vec3::ZERO),
                n.radiance / n.weight,
                Vec3::ZERO,
            );
        }
    }

    /// Records why the path stopped at `node` (when there is a log and a node).
    pub fn note(log: Option<&mut TraceLog>, node: Option<usize>, text: &str) {
        if let (Some(log), Some(me)) = (log, node) {
            log.nodes[me].note = Some(text.to_string());
        }
    }

    /// Indented text, one ray per block.
    #[must_use]
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        if !self.nodes.is_empty() {
            self.write_node(0, &mut out);
        }
        out
    }

    fn write_node(&self, i: usize, out: &mut String) {
        let n = &self.nodes[i];
        let pad = "  ".repeat(n.depth as usize);
        out.push_str(&format!(
            "{pad}{:?} ray depth {} from {} dir {} weight {}\n",
            n.kind,
            n.depth,
            v3(n.origin),
            v3(n.dir),
            v3(n.weight)
        ));
        match &n.hit {
            Some(h) => out.push_str(&format!(
                "{pad}  hit `{}` (material `{}`) at t={:.5} p={} n={} {}\n",
                h.object,
                h.material,
                h.t,
                v3(h.point),
                v3(h.normal),
                if h.entering {
                    "from outside"
                } else {
                    "from inside"
                }
            )),
            None => out.push_str(&format!("{pad}  miss: background\n")),
        }
        for s in &n.shadows {
            out.push_str(&format!(
                "{pad}  shadow ray to light {} dir {}: {}\n",
                s.light,
                v3(s.dir),
                if s.occluded {
                    "blocked".to_string()
                } else {
                    format!("lit, adds {}", v3(s.contribution))
                }
            ));
        }
        if let Some(note) = &n.note {
            out.push_str(&format!("{pad}  {note}\n"));
        }
        for &c in &n.children {
            self.write_node(c, out);
        }
        out.push_str(&format!("{pad}  => radiance {}\n", v3(n.radiance)));
    }

    /// The tree as JSON.
    #[must_use]
    pub fn to_json(&self) -> serde_json::Value {
        use serde_json::json;
        let arr = |v: Vec3| json!([v.x, v.y, v.z]);
        let nodes: Vec<_> = self
            .nodes
            .iter()
            .map(|n| {
                json!({
                    "depth": n.depth,
                    "kind": format!("{:?}", n.kind),
                    "origin": arr(n.origin),
                    "dir": arr(n.dir),
                    "weight": arr(n.weight),
                    "hit": n.hit.as_ref().map(|h| json!({
                        "t": h.t, "point": arr(h.point), "normal": arr(h.normal),
                        "object": h.object, "material": h.material, "entering": h.entering,
                    })),
                    "shadows": n.shadows.iter().map(|s| json!({
                        "light": s.light, "dir": arr(s.dir), "occluded": s.occluded, "contribution": arr(s.contribution),
                        "blocker": s.blocker.as_ref().map(|(name, t)| json!({"object": name, "t": t})),
                    })).collect::<Vec<_>>(),
                    "radiance": arr(n.radiance),
                    "children": n.children,
                    "note": n.note,
                })
            })
            .collect();
        json!({ "nodes": nodes })
    }
}
