//! The render pipeline of het-bssrdf, between the tracer and the commands: a render job and its
//! outcome ([`job`]), the files a render writes ([`files`]), renders split into shards
//! ([`sharding`]) and merged back ([`shard_merge`]), progress bars ([`progress`]) and what every
//! sidecar says about its writer ([`provenance`]). The studies (`het-bssrdf-experiments`) and
//! the command line build on it.
#![deny(missing_docs)]

pub mod files;
pub mod job;
pub mod progress;
pub mod provenance;
pub mod shard_merge;
pub mod sharding;
