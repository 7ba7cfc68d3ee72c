//! Helpers shared by the tests of every crate (taken as a dev-dependency, never by library code):
//! where the shared dataset and documents live ([`shared_data_root`], [`shared_docs_root`]), fresh temporary directories
//! ([`TempDir`]), corrupted copies of real files for the loaders' robustness tests
//! ([`corrupt`]), adversarial directions and features for the numerics stress tests
//! ([`adversarial`]), the tiny sweep profile of the tests that run whole sweeps
//! ([`tiny_profile`]), the sphere-over-plane mesh of the scene tests ([`mesh`]) and
//! element-wise closeness checks ([`assert_close`], [`assert_close_scaled`]).

pub mod adversarial;
mod close;
pub mod corrupt;
pub mod mesh;
mod profile;
mod shared_data;
mod temp_dir;

pub use close::{assert_close, assert_close_scaled};
pub use profile::{TinyProfile, tiny_profile};
pub use shared_data::{shared_data_root, shared_docs_root};
pub use temp_dir::TempDir;
