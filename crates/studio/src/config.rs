//! What `mcctrace studio` asks for ([`Config`]): the scene or project to open, the collage to
//! start from, where to listen, and how much the engine renders.

use crate::engine::EngineSettings;
use std::net::{IpAddr, Ipv4Addr};
use std::path::PathBuf;

/// What `mcctrace studio` asks for.
#[derive(Clone, Debug)]
pub struct Config {
    /// The scene file; `None` opens the project in [`Config::project`].
    pub scene: Option<PathBuf>,
    /// The project folder: saves go there; without a scene it is opened.
    pub project: PathBuf,
    /// Cameras to start with, by name (all the scene's when empty).
    pub cameras: Vec<String>,
    /// Collage width and height (`None`: the collage's own size when one is given, else
    /// [`Config::DEFAULT_RES`]).
    pub res: Option<[u32; 2]>,
    /// The first key's frame.
    pub frame: u32,
    /// An existing collage (a tagged image or layered file, e.g. cut in an editor) to start from.
    pub collage: Option<PathBuf>,
    /// The address to listen on (loopback unless asked otherwise).
    pub listen: IpAddr,
    /// The port (0: any free one).
    pub port: u16,
    /// How much the engine renders.
    pub engine: EngineSettings,
    /// The URL's token (`None`: a random one; tests fix it).
    pub token: Option<String>,
}

impl Config {
    /// The resolution of a new collage when neither `--res` nor a collage gives one.
    pub const DEFAULT_RES: [u32; 2] = [480, 270];

    /// A new session on `scene`, saving to `project`, with the defaults.
    pub fn new(scene: Option<PathBuf>, project: PathBuf) -> Self {
        Self {
            scene,
            project,
            cameras: Vec::new(),
            res: None,
            frame: 0,
            collage: None,
            listen: IpAddr::V4(Ipv4Addr::LOCALHOST),
            port: 0,
            engine: EngineSettings::default(),
            token: None,
        }
    }
}
