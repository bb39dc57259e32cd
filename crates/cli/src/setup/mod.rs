//! What the rendering commands share (docs/design/workflow.md §8): their argument groups and how those
//! become library jobs — the scene and its views ([`scene`]), the quality settings
//! ([`quality`]), the collage inputs of the remapper ([`collage`]) — and where renders go and
//! what is said about them ([`output`]).

pub mod collage;
pub mod output;
pub mod quality;
pub mod scene;
