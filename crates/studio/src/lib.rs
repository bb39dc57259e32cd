//! The studio (`mcctrace studio`, docs/studio.md): a local web page to paint a multicamera
//! collage and watch its rerender refine. An axum server on loopback serves the embedded page
//! and one WebSocket per tab; the engine ([`engine`]) keeps the session and streams pictures
//! made by the same library code as the batch commands (`tracer::job`, `mcc::job`, the
//! remapper); saves write a project folder the batch commands read ([`project`]).
#![warn(missing_docs)]

pub mod camera;
#[cfg(feature = "client")]
pub mod client;
pub mod config;
pub mod engine;
pub mod error;
pub mod maps;
pub mod project;
pub mod protocol;
pub mod server;
pub mod session;
pub mod source;

pub use config::Config;
pub use engine::EngineSettings;
pub use error::{Result, StudioError};
pub use server::{Running, serve};
