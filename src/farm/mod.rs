//! Render farms, above the renderer: what a `.part` film records about the render it holds
//! ([`PartMeta`], the settings hash that tells whether parts belong together) and how a render
//! is split into shards of sample indices ([`Shard`]), and how parts merge back into one film
//! ([`merge::merge_parts`]); what a plan decides ([`plan`]: the shards' ranges and budgets,
//! the resolved scene the shards render). The commands that plan, run and merge farm jobs are
//! thin files in the binary (`caustic farm`, `caustic merge`).

pub mod merge;
pub mod part_meta;
pub mod plan;
pub mod shard;

pub use part_meta::PartMeta;
pub use shard::Shard;
