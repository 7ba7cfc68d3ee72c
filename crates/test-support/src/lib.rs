//! Helpers shared by the tests of every crate (taken as a dev-dependency, never by library code):
//! where the shared dataset lives ([`shared_data_root`]) and fresh temporary directories
//! ([`TempDir`]).

mod shared_data;
mod temp_dir;

pub use shared_data::shared_data_root;
pub use temp_dir::TempDir;
