//! The scene key's building block ([`KeyHash`]): a value feeds every field that decides what it
//! renders into an FNV-1a hasher ([`Fnv`]), written so that a field or variant added later is a
//! compile error until it is fed or declared irrelevant.
//!
//! **How.** Structs are destructured without `..` (`let Self { a, b, c } = self;`, or
//! [`crate::key_hash_struct!`], which writes exactly that), so a new field is an error in the
//! destructuring; enums are matched without a wildcard arm, each variant feeding its own tag
//! first, so a new variant is an error in the `match`. A field that cannot change pixels (a
//! cache derived from the others, an acceleration structure) is bound to `_` with a comment
//! saying why. Numbers feed their little-endian bytes, floats their bit patterns (`0.0` and
//! `-0.0` differ), sequences their length first, options a presence tag: two values that differ
//! in any fed field feed different byte strings. The key never goes through `Debug`, whose text
//! is for people and may leave fields out.
//!
//! The settings enums (shared by every layer) feed their scene-file names, which
//! `settings_enum!` derives from the variants, so they are exhaustive by construction.

use std::sync::Arc;

use glam::{DAffine3, DMat3, DMat4, DVec3, Mat3, Mat4, Vec2, Vec3, Vec4};

use super::Fnv;
use crate::settings::{IntegratorKind, SamplerKind, TextureFilter, Tonemap};

/// A value that feeds everything that decides its rendering into a scene key (module docs).
pub trait KeyHash {
    /// Feeds `self` into `h`.
    fn key_hash(&self, h: &mut Fnv);
}

/// Implements [`KeyHash`] for a struct by destructuring it with every field named, none left
/// out (`key_hash_struct!(Phong { specular, exponent })`): a field added to the struct and not
/// to the list fails to compile. Invoke it where the fields are visible (the struct's module).
#[macro_export]
macro_rules! key_hash_struct {
    ($t:ident $(<$($g:tt),*>)? { $($f:ident),* $(,)? }) => {
        impl $(<$($g),*>)? $crate::binfile::KeyHash for $t $(<$($g),*>)? {
            fn key_hash(&self, h: &mut $crate::binfile::Fnv) {
                let Self { $($f),* } = self;
                h.str(stringify!($t));
                $( $crate::binfile::KeyHash::key_hash($f, h); )*
            }
        }
    };
}

impl Fnv {
    /// Feeds a string: its length, then its bytes.
    pub fn str(&mut self, s: &str) {
        self.u64(s.len() as u64);
        self.bytes(s.as_bytes());
    }
}

impl KeyHash for f32 {
    fn key_hash(&self, h: &mut Fnv) {
        h.f32(*self);
    }
}

impl KeyHash for f64 {
    fn key_hash(&self, h: &mut Fnv) {
        h.u64(self.to_bits());
    }
}

impl KeyHash for u8 {
    fn key_hash(&self, h: &mut Fnv) {
        h.bytes(&[*self]);
    }
}

impl KeyHash for u32 {
    fn key_hash(&self, h: &mut Fnv) {
        h.u32(*self);
    }
}

impl KeyHash for u64 {
    fn key_hash(&self, h: &mut Fnv) {
        h.u64(*self);
    }
}

impl KeyHash for usize {
    fn key_hash(&self, h: &mut Fnv) {
        h.u64(*self as u64);
    }
}

impl KeyHash for bool {
    fn key_hash(&self, h: &mut Fnv) {
        h.bytes(&[u8::from(*self)]);
    }
}

impl KeyHash for str {
    fn key_hash(&self, h: &mut Fnv) {
        h.str(self);
    }
}

impl KeyHash for String {
    fn key_hash(&self, h: &mut Fnv) {
        h.str(self);
    }
}

impl<T: KeyHash + ?Sized> KeyHash for &T {
    fn key_hash(&self, h: &mut Fnv) {
        (**self).key_hash(h);
    }
}

impl<T: KeyHash + ?Sized> KeyHash for Arc<T> {
    fn key_hash(&self, h: &mut Fnv) {
        (**self).key_hash(h);
    }
}

impl<T: KeyHash> KeyHash for Option<T> {
    fn key_hash(&self, h: &mut Fnv) {
        match self {
            None => h.bytes(&[0]),
            Some(v) => {
                h.bytes(&[1]);
                v.key_hash(h);
            }
        }
    }
}

impl<T: KeyHash> KeyHash for [T] {
    fn key_hash(&self, h: &mut Fnv) {
        h.u64(self.len() as u64);
        for v in self {
            v.key_hash(h);
        }
    }
}

impl<T: KeyHash> KeyHash for Vec<T> {
    fn key_hash(&self, h: &mut Fnv) {
        self.as_slice().key_hash(h);
    }
}

impl<T: KeyHash, const N: usize> KeyHash for [T; N] {
    fn key_hash(&self, h: &mut Fnv) {
        for v in self {
            v.key_hash(h);
        }
    }
}

impl<A: KeyHash, B: KeyHash> KeyHash for (A, B) {
    fn key_hash(&self, h: &mut Fnv) {
        self.0.key_hash(h);
        self.1.key_hash(h);
    }
}

/// Feeds glam types as their components in memory order.
macro_rules! key_hash_glam {
    ($($t:ty => $arr:ident),* $(,)?) => {
        $(impl KeyHash for $t {
            fn key_hash(&self, h: &mut Fnv) {
                self.$arr().key_hash(h);
            }
        })*
    };
}

key_hash_glam!(
    Vec2 => to_array,
    Vec3 => to_array,
    Vec4 => to_array,
    DVec3 => to_array,
    Mat3 => to_cols_array,
    Mat4 => to_cols_array,
    DMat3 => to_cols_array,
    DMat4 => to_cols_array,
);

impl KeyHash for DAffine3 {
    fn key_hash(&self, h: &mut Fnv) {
        self.to_cols_array().key_hash(h);
    }
}

/// Feeds the settings enums as their scene-file names (exhaustive: `settings_enum!` writes
/// `name` from the variant list).
macro_rules! key_hash_settings {
    ($($t:ty),* $(,)?) => {
        $(impl KeyHash for $t {
            fn key_hash(&self, h: &mut Fnv) {
                h.str(self.name());
            }
        })*
    };
}

key_hash_settings!(IntegratorKind, SamplerKind, TextureFilter, Tonemap);

#[cfg(test)]
mod tests {
    use super::*;

    fn key(v: &impl KeyHash) -> u64 {
        let mut h = Fnv::new();
        v.key_hash(&mut h);
        h.finish()
    }

    #[test]
    fn sequences_and_options_are_delimited() {
        // Without the length and presence tags these pairs would feed the same bytes.
        assert_ne!(
            key(&(vec![1u32], vec![2u32, 3])),
            key(&(vec![1u32, 2], vec![3u32]))
        );
        assert_ne!(
            key(&(None::<u32>, Some(0u32))),
            key(&(Some(0u32), None::<u32>))
        );
        assert_ne!(key(&0.0f32), key(&-0.0f32));
        assert_eq!(key(&Vec3::new(1.0, 2.0, 3.0)), key(&[1.0f32, 2.0, 3.0]));
    }

    #[test]
    fn settings_enums_feed_distinct_names() {
        let keys: std::collections::BTreeSet<u64> = IntegratorKind::ALL.iter().map(key).collect();
        assert_eq!(keys.len(), IntegratorKind::ALL.len());
    }
}
