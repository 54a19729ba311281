//! What the `wirepass` command, the tests and the benchmarks are built from, over the
//! library: scenes loaded from files and specs ([`load`], [`scene_file`]), offscreen frames
//! of every method and their dumps ([`offline`]), what a pixel shows ([`pick`](mod@pick)), the comparison against the ground truth
//! ([`compare`]), the benchmark ([`bench`](mod@bench)) and image regression ([`regression`]).
//!
//! Everything here may use the whole library below it (the pass, the loaders, the ground
//! truth); nothing in the library uses it.

#[cfg(feature = "tools")]
pub mod bench;
#[cfg(feature = "tools")]
pub mod compare;
#[cfg(all(feature = "tools", not(target_arch = "wasm32")))]
pub mod gs;
#[cfg(feature = "tools")]
pub mod load;
#[cfg(feature = "tools")]
pub mod offline;
#[cfg(feature = "tools")]
pub mod pick;
#[cfg(feature = "tools")]
pub mod pipeline_cache;
#[cfg(feature = "regression")]
pub mod regression;
#[cfg(feature = "tools")]
pub mod scene_file;
