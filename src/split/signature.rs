//! What a structure is, to refuse a model of another: a [`Signature`], every size of a
//! compiled model but [`SIGNATURE_SKIPPED_SIZES`], its names buffer and the integer arrays
//! [`SIGNATURE_ARRAYS`]. The one definition both faces' model caches take, each reading a
//! model through its own MuJoCo ([`SignatureSource`]: the linked library's size table in
//! `compiled/store.rs`, the user's `MjModel` in `python/src/split/tables.rs`).
//!
//! ```
//! use mjcf_forge::split::{Signature, SignatureSource};
//!
//! struct Model(i64);
//! impl SignatureSource for Model {
//!     fn sizes(&self) -> Vec<(String, i64)> {
//!         vec![("nbody".into(), self.0), ("ngravcomp".into(), 1)]
//!     }
//!     fn names_buffer(&self) -> Vec<u8> {
//!         b"world\0".to_vec()
//!     }
//!     fn array_bytes(&self, _name: &str) -> Vec<u8> {
//!         Vec::new()
//!     }
//! }
//! assert_eq!(Signature::of(&Model(2)), Signature::of(&Model(2)));
//! assert_ne!(Signature::of(&Model(2)), Signature::of(&Model(3)));
//! ```

use super::targets::{SIGNATURE_ARRAYS, SIGNATURE_SKIPPED_SIZES};

/// A compiled model as its MuJoCo shows it to a [`Signature`].
pub trait SignatureSource {
    /// Every size of the model, by name, in one order per MuJoCo.
    fn sizes(&self) -> Vec<(String, i64)>;
    /// The model's names buffer.
    fn names_buffer(&self) -> Vec<u8>;
    /// The bytes of the integer array `name`; empty where this MuJoCo has none.
    fn array_bytes(&self, name: &str) -> Vec<u8>;
}

/// What decides a compiled model's structure.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Signature {
    sizes: Vec<i64>,
    names: Vec<u8>,
    arrays: Vec<Vec<u8>>,
}

impl Signature {
    /// The signature of `model`.
    pub fn of(model: &impl SignatureSource) -> Signature {
        let sizes = model
            .sizes()
            .into_iter()
            .filter(|(name, _)| !SIGNATURE_SKIPPED_SIZES.contains(&name.as_str()))
            .map(|(_, value)| value)
            .collect();
        Signature {
            sizes,
            names: model.names_buffer(),
            arrays: SIGNATURE_ARRAYS
                .iter()
                .map(|name| model.array_bytes(name))
                .collect(),
        }
    }

    /// The signature as bytes (equal bytes, equal signatures): each part with its length.
    pub fn to_bytes(&self) -> Vec<u8> {
        let mut out = Vec::new();
        let mut part = |bytes: &[u8]| {
            out.extend_from_slice(&(bytes.len() as u64).to_le_bytes());
            out.extend_from_slice(bytes);
        };
        let sizes: Vec<u8> = self.sizes.iter().flat_map(|s| s.to_le_bytes()).collect();
        part(&sizes);
        part(&self.names);
        for a in &self.arrays {
            part(a);
        }
        out
    }
}
