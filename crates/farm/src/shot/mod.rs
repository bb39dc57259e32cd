//! One MCC shot as the farm sees it (docs/farm.md, "Schedulers"): the scene, the key frames with
//! their cameras and collages, the output frames and how they are rendered, the resources to
//! ask for; and its [`Plan`], the `mcctrace` command of every stage, which the Slurm and Open Job
//! Description writers both turn into jobs.

use crate::{Result, bad};
use std::path::{Path, PathBuf};

/// A key frame: the cameras whose views are rendered at it and the collage cut from them.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Key {
    /// The key's frame.
    pub frame: u32,
    /// Its cameras (names or indices, as `render --camera` takes them), numbered 1, 2, … in order.
    pub cameras: Vec<String>,
    /// The collage cut from those views (an image, or a layered .ora / .psd file).
    pub collage: PathBuf,
    /// Its region image, if any (else `keys` looks beside the collage).
    pub regions: Option<PathBuf>,
}

/// An inclusive range of frames.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FrameSpan {
    /// The first frame.
    pub first: u32,
    /// The last frame (inclusive).
    pub last: u32,
}

impl FrameSpan {
    /// How many frames the span holds.
    pub fn len(self) -> u64 {
        u64::from(self.last - self.first) + 1
    }

    /// Whether the span holds no frame (never, for a valid span).
    pub fn is_empty(self) -> bool {
        self.last < self.first
    }
}

impl std::fmt::Display for FrameSpan {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}..={}", self.first, self.last)
    }
}

/// How one kind of picture is rendered: its size and samples, and any further `mcctrace` flags.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Pass {
    /// Width and height in pixels.
    pub res: (u32, u32),
    /// Samples per pixel.
    pub spp: u32,
    /// Further flags passed as they are (like `--seed 7`).
    pub args: Vec<String>,
}

impl Pass {
    fn flags(&self) -> Vec<String> {
        let mut v = vec![
            "--res".into(),
            format!("{}x{}", self.res.0, self.res.1),
            "--spp".into(),
            self.spp.to_string(),
        ];
        v.extend(self.args.iter().cloned());
        v
    }

    fn check(&self, res_flag: &'static str, spp_flag: &'static str) -> Result<()> {
        if self.res.0 == 0 || self.res.1 == 0 {
            return Err(bad(res_flag, format!("{}x{} has a zero dimension", self.res.0, self.res.1)));
        }
        if self.spp == 0 {
            return Err(bad(spp_flag, "0 samples per pixel: need at least 1"));
        }
        Ok(())
    }

    /// Samples one picture takes.
    fn samples(&self) -> u64 {
        u64::from(self.res.0) * u64::from(self.res.1) * u64::from(self.spp)
    }
}

/// What the tasks ask the scheduler for; `None` takes a default derived from the render settings
/// ([`Plan::resources`]).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Resources {
    /// CPUs per task.
    pub cpus: Option<u32>,
    /// Memory per task, MiB.
    pub mem_mib: Option<u64>,
    /// Time limit per task, minutes.
    pub time_minutes: Option<u32>,
    /// The partition (queue); the cluster's default if `None`.
    pub partition: Option<String>,
    /// The largest node the tasks can run on, when known (`sinfo`, on `--submit`): defaults are
    /// fitted to it and a flag asking more is refused, since such a task would pend forever.
    pub node: Option<NodeSize>,
}

/// What the largest node of a cluster (or partition) offers one task.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NodeSize {
    /// CPUs.
    pub cpus: u32,
    /// Memory, MiB.
    pub mem_mib: u64,
}

/// The whole shot.
#[derive(Clone, Debug, PartialEq)]
pub struct Shot {
    /// The `mcctrace` program the tasks run.
    pub mcctrace: PathBuf,
    /// The scene file (or folder of OBJ files).
    pub scene: PathBuf,
    /// The shot folder, shared by every task: `views/`, `lens/`, `frames/`, `logs/` and the jobs.
    pub dir: PathBuf,
    /// The key frames.
    pub keys: Vec<Key>,
    /// The output frames.
    pub frames: FrameSpan,
    /// Output frames per task.
    pub chunk: u32,
    /// The source views.
    pub views: Pass,
    /// The output frames (through the in-betweened rays).
    pub output: Pass,
    /// Further flags of `keys` (like `--seamless`, `--mode linear`).
    pub keys_args: Vec<String>,
    /// What each task asks for.
    pub resources: Resources,
}

/// A stage of the shot, in the order they run.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Stage {
    /// The source views of every key frame, one task per key frame and camera.
    Views,
    /// `keys`: every key remapped, every frame's rays in-betweened (one task).
    Keys,
    /// The output frames, one task per chunk.
    Frames,
    /// Every frame checked (`animate --check`), the preview written (one task).
    Check,
}

impl Stage {
    /// Every stage, in order.
    pub const ALL: [Stage; 4] = [Stage::Views, Stage::Keys, Stage::Frames, Stage::Check];

    /// Its name in file and job names.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Views => "views",
            Stage::Keys => "keys",
            Stage::Frames => "frames",
            Stage::Check => "check",
        }
    }
}

/// A word of a task's command: text, or a value that differs from task to task.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Word {
    /// The same in every task.
    Text(String),
    /// A view task's key frame.
    KeyFrame,
    /// A view task's camera.
    Camera,
    /// A view task's view number.
    ViewId,
    /// A frame task's frames, `A..=B`.
    Frames,
    /// The whole shot's frames, `A..=B` (a job parameter where the scheduler has them).
    ShotFrames,
    /// A still's band task's `--tile` value, `I/N` with this N (docs/farm.md, "Big stills").
    Tile(u32),
}

/// One source view to render.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ViewTask {
    /// The key frame.
    pub frame: u32,
    /// The camera.
    pub camera: String,
    /// Its view number (1-based, in the key's camera order).
    pub id: u32,
}

impl Resources {
    /// Refuses what no scheduler takes, naming the flag.
    pub(crate) fn check(&self) -> Result<()> {
        if self.cpus == Some(0) {
            return Err(bad("--cpus-per-task", "0 CPUs: need at least 1"));
        }
        if self.mem_mib == Some(0) {
            return Err(bad("--mem", "0 MiB: need some memory"));
        }
        if self.time_minutes == Some(0) {
            return Err(bad("--time", "a time limit of 0 minutes: need at least 1"));
        }
        if let Some(p) = &self.partition
            && (p.is_empty() || !p.chars().all(|c| c.is_ascii_alphanumeric() || "-_.,".contains(c)))
        {
            return Err(bad(
                "--partition",
                format!("{p:?} is not a partition name (letters, digits, - _ . ,)"),
            ));
        }
        let Some(node) = self.node else { return Ok(()) };
        let nodes = match &self.partition {
            Some(p) => format!("partition {p}'s largest node"),
            None => "the cluster's largest node".to_owned(),
        };
        if let Some(cpus) = self.cpus.filter(|&c| c > node.cpus) {
            return Err(bad(
                "--cpus-per-task",
                format!(
                    "{cpus} CPUs per task, but {nodes} has {} (sinfo): the tasks would pend forever; \
                     give --cpus-per-task {} or less",
                    node.cpus, node.cpus
                ),
            ));
        }
        if let Some(mem) = self.mem_mib.filter(|&m| m > node.mem_mib) {
            return Err(bad(
                "--mem",
                format!(
                    "{mem} MiB per task, but {nodes} has {} MiB (sinfo): the tasks would pend forever; \
                     give --mem {}M or less",
                    node.mem_mib, node.mem_mib
                ),
            ));
        }
        Ok(())
    }

    /// These resources, defaults filled in for a task over a picture of `pixels` pixels, tracing
    /// `samples` samples (0: renders nothing) and holding `layers` pictures' worth of memory.
    pub(crate) fn for_task(&self, pixels: u64, samples: u64, layers: u64) -> StageResources {
        // Small pictures do not pay for a second thread's start-up; larger ones get four.
        let default_cpus = if samples == 0 || pixels <= 256 * 256 { 1 } else { 4 };
        let default_mem = BASE_MIB + (pixels * BYTES_PER_PIXEL * layers).div_ceil(1 << 20);
        // Fitted to the largest node, if known: a task asking more than any node has never starts.
        let fitted_cpus = self.node.map_or(default_cpus, |n| default_cpus.min(n.cpus.max(1)));
        let fitted_mem = self.node.map_or(default_mem, |n| default_mem.min(n.mem_mib.max(1)));
        let cpus = self.cpus.unwrap_or(fitted_cpus);
        let mem_mib = self.mem_mib.unwrap_or(fitted_mem);
        let lowered = (self.cpus.is_none() && fitted_cpus < default_cpus).then_some(default_cpus);
        let lowered_mem = (self.mem_mib.is_none() && fitted_mem < default_mem).then_some(default_mem);
        let minutes = (samples / (SAMPLES_PER_CPU_SECOND * u64::from(cpus))).div_ceil(60);
        let time_minutes =
            self.time_minutes.unwrap_or((4 * minutes).max(LEAST_MINUTES).min(u64::from(u32::MAX)) as u32);
        StageResources { cpus, mem_mib, time_minutes, node: self.node, lowered: (lowered, lowered_mem) }
    }
}

/// Resources of one stage's tasks, defaults filled in.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StageResources {
    /// CPUs per task.
    pub cpus: u32,
    /// Memory per task, MiB.
    pub mem_mib: u64,
    /// Time limit per task, minutes.
    pub time_minutes: u32,
    /// The node the defaults were fitted to (`None`: the cluster is not known).
    pub node: Option<NodeSize>,
    /// The default CPUs and memory before fitting, where fitting lowered them.
    pub lowered: (Option<u32>, Option<u64>),
}

impl StageResources {
    /// What a stage's script says of its resources: fitted to the cluster's largest node (and
    /// what fitting lowered), or the assumption made without knowing the cluster.
    pub fn note(&self) -> String {
        let (cpus, mem) = (self.cpus, self.mem_mib);
        match (self.node, self.lowered) {
            (None, _) => format!(
                "each task asks {cpus} CPUs and {mem} MiB: a cluster with no node that large keeps it \
                 pending for ever (squeue: PartitionConfig or Resources); give --cpus-per-task / \
                 --mem, or submit with `mcctrace farm slurm --submit`, which fits the defaults to the \
                 cluster's nodes"
            ),
            (Some(n), (None, None)) => {
                format!(
                    "each task asks {cpus} CPUs and {mem} MiB; the largest node has {} and {} MiB",
                    n.cpus, n.mem_mib
                )
            }
            (Some(n), (c, m)) => {
                let mut lowered = Vec::new();
                if let Some(c) = c {
                    lowered.push(format!("{cpus} CPUs per task instead of the default {c}"));
                }
                if let Some(m) = m {
                    lowered.push(format!("{mem} MiB instead of the default {m}"));
                }
                format!(
                    "{}: the cluster's largest node has {} CPUs and {} MiB (sinfo)",
                    lowered.join(", "),
                    n.cpus,
                    n.mem_mib
                )
            }
        }
    }

    /// Whether fitting to the cluster lowered a default.
    pub fn was_lowered(&self) -> bool {
        self.lowered != (None, None)
    }
}

/// The shot's tasks: what every stage runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Plan {
    /// The shot, its paths made absolute.
    pub shot: Shot,
    /// The view tasks, key by key.
    pub views: Vec<ViewTask>,
    /// The frame tasks' chunks, in order.
    pub chunks: Vec<FrameSpan>,
}

/// Defaults are conservative: a task killed for its limits costs more than one that asked for
/// too much. Samples per CPU-second assumed for the time limit (well below the bundled scenes'
/// throughput, for heavier scenes), and the least time asked.
const SAMPLES_PER_CPU_SECOND: u64 = 100_000;
const LEAST_MINUTES: u64 = 30;
/// Memory: a base for the program and scene, plus bytes per pixel (film, AOVs, two frames' rays).
const BASE_MIB: u64 = 1024;
const BYTES_PER_PIXEL: u64 = 512;

fn absolute(path: &Path, flag: &'static str) -> Result<PathBuf> {
    std::path::absolute(path).map_err(|e| bad(flag, format!("{}: {e}", path.display())))
}

impl Shot {
    /// Checks the shot and plans its tasks; every error names the flag to fix.
    pub fn plan(&self) -> Result<Plan> {
        let mut shot = self.clone();
        if shot.keys.is_empty() {
            return Err(bad("--key", "a shot needs at least one key (FRAME=COLLAGE)"));
        }
        shot.keys.sort_by_key(|k| k.frame);
        for pair in shot.keys.windows(2) {
            if pair[0].frame == pair[1].frame {
                return Err(bad(
                    "--key",
                    format!("frame {} has two keys; each frame takes one", pair[0].frame),
                ));
            }
        }
        for k in &shot.keys {
            if k.cameras.is_empty() {
                return Err(bad(
                    "--cameras",
                    format!(
                        "the key at frame {} has no cameras: give --cameras {}=CAMERA[,CAMERA…]",
                        k.frame, k.frame
                    ),
                ));
            }
            if let Some(c) = k.cameras.iter().find(|c| c.trim().is_empty()) {
                return Err(bad(
                    "--cameras",
                    format!("the key at frame {} names an empty camera {c:?}", k.frame),
                ));
            }
        }
        if shot.chunk == 0 {
            return Err(bad("--chunk", "0 frames per task: need at least 1"));
        }
        shot.views.check("--view-res", "--view-spp")?;
        shot.output.check("--res", "--spp")?;
        shot.resources.check()?;
        if !shot.scene.exists() {
            return Err(bad("SCENE", format!("{}: no such file or folder", shot.scene.display())));
        }
        shot.scene = absolute(&shot.scene, "SCENE")?;
        shot.dir = absolute(&shot.dir, "--dir")?;
        shot.mcctrace = absolute(&shot.mcctrace, "--mcctrace")?;
        for k in &mut shot.keys {
            for file in std::iter::once(&mut k.collage).chain(k.regions.as_mut()) {
                if !file.is_file() {
                    return Err(bad(
                        "--key",
                        format!("key at frame {}: {} is not a file", k.frame, file.display()),
                    ));
                }
                *file = absolute(file, "--key")?;
            }
        }
        let views = shot
            .keys
            .iter()
            .flat_map(|k| {
                (1..).zip(&k.cameras).map(|(id, c)| ViewTask { frame: k.frame, camera: c.clone(), id })
            })
            .collect();
        let chunks = (shot.frames.first..=shot.frames.last)
            .step_by(shot.chunk as usize)
            .map(|a| FrameSpan { first: a, last: a.saturating_add(shot.chunk - 1).min(shot.frames.last) })
            .collect();
        Ok(Plan { shot, views, chunks })
    }
}

impl Plan {
    /// `dir/name`.
    pub fn path(&self, name: &str) -> PathBuf {
        self.shot.dir.join(name)
    }

    /// A path as a command word.
    fn word(path: &Path) -> Word {
        Word::Text(path.display().to_string())
    }

    fn text<const N: usize>(words: [&str; N]) -> impl Iterator<Item = Word> {
        words.into_iter().map(|w| Word::Text(w.to_owned()))
    }

    /// The command a stage's task runs (after the `mcctrace` program itself).
    pub fn command(&self, stage: Stage) -> Vec<Word> {
        let s = &self.shot;
        let mut c = Vec::new();
        match stage {
            Stage::Views => {
                c.extend(Self::text(["render"]));
                c.push(Self::word(&s.scene));
                c.extend(Self::text(["--camera"]));
                c.push(Word::Camera);
                c.extend(Self::text(["--first-id"]));
                c.push(Word::ViewId);
                c.extend(Self::text(["--frame"]));
                c.push(Word::KeyFrame);
                c.extend(Self::text(["--lens-writer", "--tag", "--resume", "--out"]));
                c.push(Self::word(&self.path("views")));
                c.extend(s.views.flags().into_iter().map(Word::Text));
            }
            Stage::Keys => {
                c.extend(Self::text(["keys"]));
                for k in &s.keys {
                    c.extend(Self::text(["--key"]));
                    let regions = k.regions.as_ref().map(|r| format!(",{}", r.display())).unwrap_or_default();
                    c.push(Word::Text(format!("{}={}{regions}", k.frame, k.collage.display())));
                }
                c.extend(Self::text(["--rays"]));
                c.push(Self::word(&self.path("views")));
                c.extend(Self::text(["--frames"]));
                c.push(Word::ShotFrames);
                c.extend(Self::text(["--out"]));
                c.push(Self::word(&self.path("lens")));
                c.extend(Self::text(["--res"]));
                c.push(Word::Text(format!("{}x{}", s.output.res.0, s.output.res.1)));
                c.extend(s.keys_args.iter().cloned().map(Word::Text));
            }
            Stage::Frames | Stage::Check => {
                c.extend(Self::text(["animate"]));
                c.push(Self::word(&s.scene));
                c.extend(Self::text(["--lens-dir"]));
                c.push(Self::word(&self.path("lens")));
                c.extend(Self::text(["--frames"]));
                c.push(if stage == Stage::Frames { Word::Frames } else { Word::ShotFrames });
                c.extend(Self::text(["--out"]));
                c.push(Self::word(&self.path("frames")));
                c.extend(s.output.flags().into_iter().map(Word::Text));
                if stage == Stage::Frames {
                    c.extend(Self::text(["--preview", "none"]));
                } else {
                    c.extend(Self::text(CHECK_FLAGS));
                }
            }
        }
        c
    }

    /// How many tasks a stage has.
    pub fn tasks(&self, stage: Stage) -> usize {
        match stage {
            Stage::Views => self.views.len(),
            Stage::Frames => self.chunks.len(),
            Stage::Keys | Stage::Check => 1,
        }
    }

    /// A stage's resources: the shot's, or defaults from its render settings.
    pub fn resources(&self, stage: Stage) -> StageResources {
        let s = &self.shot;
        let (pixels, samples) = match stage {
            Stage::Views => (s.views.res, s.views.samples()),
            Stage::Frames => (s.output.res, s.output.samples() * u64::from(s.chunk)),
            // In-betweening holds every key's rays and writes one file per frame.
            Stage::Keys => (s.views.res.max(s.output.res), 0),
            Stage::Check => (s.output.res, 0),
        };
        let pixels = u64::from(pixels.0) * u64::from(pixels.1);
        let layers = if stage == Stage::Keys { 2 + s.keys.len() as u64 } else { 1 };
        s.resources.for_task(pixels, samples, layers)
    }
}

/// What the check stage adds to `animate` over the whole shot: render nothing, name every
/// missing, damaged or stale frame and fail if there is one, else write the preview.
const CHECK_FLAGS: [&str; 1] = ["--check"];

mod inputs;
#[cfg(test)]
pub(crate) mod tests;
