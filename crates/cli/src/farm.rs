//! `mcctrace farm`: a whole MCC shot as render-farm jobs (docs/farm.md, "Schedulers"): the
//! arguments describe the shot as `render`, `keys` and `animate` would take it; or, with
//! `--bands N -- COMMAND`, one big still (`render` or `rerender`) cut into N bands and merged
//! (docs/farm.md, "Big stills"). The `farm` library writes the Slurm scripts (and submits them
//! with `--submit`) or the Open Job Description template.

use crate::args::{FrameRange, KeyArg, Resolution, Shutter};
use crate::inbetween::ModeArg;
use anyhow::{Context, bail};
use clap::{Args, Parser, Subcommand, ValueEnum};
use farm::shot::Stage;
use farm::{FrameSpan, Key, Pass, Resources, Shot, Still, StillStage};
use std::path::PathBuf;
use tracer::job::{Quality, SceneSetup};

/// Arguments of `mcctrace farm`.
#[derive(Args, Debug)]
pub struct FarmArgs {
    #[command(subcommand)]
    scheduler: Scheduler,
}

#[derive(Subcommand, Debug)]
enum Scheduler {
    /// Slurm batch scripts in DIR/slurm/ (views and frames as job arrays, afterok dependencies)
    /// and submit.sh; --submit submits them with sbatch.
    Slurm(SlurmArgs),
    /// An Open Job Description template, DIR/openjd-template.yaml (`openjd run` runs it
    /// locally; AWS Deadline Cloud takes it as a job bundle's template).
    Openjd(JobArgs),
}

#[derive(Args, Debug)]
struct SlurmArgs {
    #[command(flatten)]
    job: JobArgs,
    /// Submit the stages with sbatch (each after the one before) and print their job ids.
    #[arg(long)]
    submit: bool,
}

/// A shot (the flags below), or a still (`--bands N -- COMMAND`), and what every task asks
/// for.
#[derive(Args, Debug)]
struct JobArgs {
    #[command(flatten)]
    shot: ShotArgs,
    /// A big still instead of a shot: the `render` or `rerender` command after `--`, cut into N
    /// horizontal bands (one task each, `--tile I/N`), then merged into its --out.
    #[arg(long, value_name = "N", requires = "command", conflicts_with_all = SHOT_ONLY)]
    bands: Option<u32>,
    /// With --bands: the still's command, word for word as run locally (`render SCENE … --out
    /// BIG.exr` or `rerender …`), without --tile. It runs in this folder.
    #[arg(last = true, value_name = "COMMAND", requires = "bands")]
    command: Vec<String>,
    /// The folder every task shares: the jobs and logs/ go here (for a shot also views/, lens/
    /// and frames/).
    #[arg(long)]
    dir: PathBuf,
    /// CPUs per task (default: 1 for pictures up to 256x256, else 4).
    #[arg(long, value_name = "N")]
    cpus_per_task: Option<u32>,
    /// Memory per task, MiB or with a unit: 4096, 4G, 512M (default: from the resolution).
    #[arg(long, value_name = "SIZE", value_parser = mem_mib)]
    mem: Option<u64>,
    /// Time limit per task: MINUTES, H:MM:SS or D-H:MM:SS (default: from the samples per task).
    #[arg(long, value_name = "TIME", value_parser = minutes)]
    time: Option<u32>,
    /// The partition (queue) to run in (default: the cluster's).
    #[arg(long)]
    partition: Option<String>,
    /// The mcctrace program the tasks run (default: this one). It must be reachable from the
    /// farm's machines at this path.
    #[arg(long, value_name = "PATH")]
    mcctrace: Option<PathBuf>,
    /// The cluster's largest node, read with `sinfo` on `--submit`.
    #[arg(skip)]
    node: Option<farm::NodeSize>,
}

/// The shot's own flags, refused beside --bands.
const SHOT_ONLY: [&str; 16] = [
    "scene",
    "keys",
    "cameras",
    "frames",
    "chunk",
    "view_res",
    "view_spp",
    "res",
    "spp",
    "seed",
    "fps",
    "max_depth",
    "shutter",
    "mode",
    "seamless",
    "denoise",
];

/// The shot: what `render` (the views), `keys` and `animate` (the frames) would be given.
#[derive(Args, Debug)]
struct ShotArgs {
    /// Scene file (.gltf, .glb, .obj) or a directory of .obj files.
    #[arg(required_unless_present = "bands")]
    scene: Option<PathBuf>,
    /// A key: FRAME=COLLAGE or FRAME=COLLAGE,REGIONS, as `keys` takes it. Repeat per key.
    #[arg(long = "key", value_name = "FRAME=COLLAGE[,REGIONS]", required_unless_present = "bands")]
    keys: Vec<KeyArg>,
    /// The cameras of a key frame's views, in view order (camera01, camera02, …), as
    /// `render --camera` names them: FRAME=CAMERA[,CAMERA…]. One per key.
    #[arg(long = "cameras", value_name = "FRAME=CAMERA[,CAMERA…]", required_unless_present = "bands")]
    cameras: Vec<KeyArg>,
    /// The output frames, FIRST..=LAST (both included) or one frame F.
    #[arg(long, value_name = "A..=B", required_unless_present = "bands")]
    frames: Option<FrameRange>,
    /// Output frames per task.
    #[arg(long, default_value_t = 10, value_name = "N")]
    chunk: u32,
    /// Resolution of the source views (the collages are cut from them at this size).
    #[arg(long, default_value = "640x360", value_name = "WxH")]
    view_res: Resolution,
    /// Samples per pixel of the source views.
    #[arg(long, default_value_t = Quality::DEFAULT.spp, value_parser = crate::args::spp)]
    view_spp: u32,
    /// Resolution of the output frames (default: the views').
    #[arg(long, value_name = "WxH")]
    res: Option<Resolution>,
    /// Samples per pixel of the output frames.
    #[arg(long, default_value_t = Quality::DEFAULT.spp, value_parser = crate::args::spp)]
    spp: u32,
    /// Seed of the sample sequence (views and frames).
    #[arg(long, default_value_t = Quality::DEFAULT.seed)]
    seed: u32,
    /// Frames per second: an animated scene is posed at frame / FPS seconds.
    #[arg(long, default_value_t = SceneSetup::DEFAULT_FPS)]
    fps: f32,
    /// Maximum scattering vertices per path (views and frames).
    #[arg(long, default_value_t = Quality::DEFAULT.max_depth)]
    max_depth: u32,
    /// Camera motion blur of the output frames, as `animate --shutter`.
    #[arg(long, value_name = "OPEN..CLOSE")]
    shutter: Option<Shutter>,
    /// Interpolation between keys, as `keys --mode`.
    #[arg(long, value_enum, default_value = "smooth")]
    mode: ModeArg,
    /// The seamless blend, as `keys --seamless`.
    #[arg(long)]
    seamless: bool,
    /// Denoise the output frames, as `animate --denoise[=QUALITY]` (the source views stay raw:
    /// the collages are painted from them).
    #[arg(long, value_name = "QUALITY", num_args = 0..=1, require_equals = true,
        default_missing_value = tracer::denoise::Quality::DEFAULT.name(), value_parser = crate::args::denoise_quality)]
    denoise: Option<tracer::denoise::Quality>,
}

/// `--mem`: a size in MiB, or with a unit K, M, G or T (Slurm's own suffixes).
fn mem_mib(s: &str) -> Result<u64, String> {
    let t = s.trim();
    let (digits, unit) = t.split_at(t.find(|c: char| !c.is_ascii_digit()).unwrap_or(t.len()));
    let n: u64 = digits.parse().map_err(|_| format!("'{s}' is not a size like 4096, 512M or 4G"))?;
    let kib = match unit.to_ascii_uppercase().as_str() {
        "K" => n,
        "" | "M" => n << 10,
        "G" => n << 20,
        "T" => n << 30,
        _ => return Err(format!("'{s}': unknown unit '{unit}' (K, M, G or T)")),
    };
    Ok(kib.div_ceil(1024))
}

/// `--time`: whole minutes, H:MM:SS or D-H:MM:SS, rounded up to minutes.
fn minutes(s: &str) -> Result<u32, String> {
    let err = || format!("'{s}' is not a time limit like 90, 1:30:00 or 2-0:00:00");
    let num = |v: &str| v.trim().parse::<u64>().map_err(|_| err());
    let (days, rest) = match s.split_once('-') {
        Some((d, rest)) => (num(d)?, rest),
        None => (0, s),
    };
    let parts: Vec<u64> = rest.split(':').map(num).collect::<Result<_, _>>()?;
    let seconds = match (s.contains('-'), parts.as_slice()) {
        (false, [m]) => m * 60,
        (_, [h, m, sec]) => h * 3600 + m * 60 + sec,
        (true, [h]) => h * 3600,
        (true, [h, m]) => h * 3600 + m * 60,
        _ => return Err(err()),
    } + days * 86400;
    u32::try_from(seconds.div_ceil(60)).map_err(|_| err())
}

/// What the farm needs from a still's command: its output and, for the default resources, its
/// size and samples.
struct StillCommand {
    out: PathBuf,
    size: (u32, u32),
    spp: u32,
}

/// Size assumed for resources when a rerender's rays cannot be sized without --res.
const ASSUMED_SIZE: (u32, u32) = (3840, 2160);

impl StillCommand {
    /// Parses the still's command as `mcctrace` would; refuses anything but one view of
    /// `render` or a `rerender`.
    fn parse(words: &[String]) -> anyhow::Result<Self> {
        let cli =
            crate::Cli::try_parse_from(std::iter::once("mcctrace").chain(words.iter().map(String::as_str)))
                .map_err(|e| anyhow::anyhow!("COMMAND (after --): {}", e.render().to_string().trim()))?;
        let (out, spp, size) = match cli.command {
            crate::Command::Render(r) => {
                if r.scene.cameras.len() > 1 {
                    bail!("--camera: a still is one view; give one --camera (farm each view on its own)");
                }
                (r.out, r.quality.spp, r.quality.resolution())
            }
            crate::Command::Rerender(r) => {
                let size = match (r.quality.res, &r.lens, &r.input.collage) {
                    (Some(res), _, _) => res.0,
                    (None, Some(lens), _) => {
                        let rays = mcc::RayFile::read(lens)?;
                        glam::UVec2::new(rays.width, rays.height)
                    }
                    (None, None, Some(collage)) => image::image_dimensions(collage)
                        .map(|(w, h)| glam::UVec2::new(w, h))
                        .unwrap_or(glam::UVec2::from(ASSUMED_SIZE)),
                    (None, None, None) => glam::UVec2::from(ASSUMED_SIZE),
                };
                (r.out, r.quality.spp, size)
            }
            _ => bail!(
                "COMMAND (after --): {:?} is not a still: give a `render` or `rerender` command",
                words.first().map(String::as_str).unwrap_or_default()
            ),
        };
        Ok(Self { out, size: (size.x, size.y), spp })
    }
}

impl JobArgs {
    fn resources(&self) -> Resources {
        Resources {
            cpus: self.cpus_per_task,
            mem_mib: self.mem,
            time_minutes: self.time,
            partition: self.partition.clone(),
            node: self.node,
        }
    }

    fn mcctrace(&self) -> anyhow::Result<PathBuf> {
        match &self.mcctrace {
            Some(p) => Ok(p.clone()),
            None => std::env::current_exe().context("finding this mcctrace program (give --mcctrace PATH)"),
        }
    }

    /// The still of `--bands N -- COMMAND`, checked; `None` for a shot.
    fn still(&self) -> anyhow::Result<Option<Still>> {
        let Some(bands) = self.bands else { return Ok(None) };
        // Refused by flag first: a --tile in the command would parse as a valid render.
        farm::still::check_command(bands, &self.command)?;
        let command = StillCommand::parse(&self.command)?;
        let still = Still {
            mcctrace: self.mcctrace()?,
            workdir: std::env::current_dir().context("finding the current folder")?,
            dir: self.dir.clone(),
            command: self.command.clone(),
            out: command.out,
            bands,
            size: command.size,
            spp: command.spp,
            resources: self.resources(),
        };
        Ok(Some(still.plan()?))
    }

    fn shot(&self) -> anyhow::Result<Shot> {
        let a = &self.shot;
        let (Some(scene), Some(frames)) = (&a.scene, a.frames) else {
            bail!("a shot needs SCENE and --frames (or --bands N -- COMMAND for a still)");
        };
        let mut keys = Vec::new();
        for k in &a.keys {
            let (collage, regions) = crate::keys::split_key(k)?;
            let cameras = a
                .cameras
                .iter()
                .filter(|c| c.frame == k.frame)
                .flat_map(|c| c.value.split(',').map(str::to_owned))
                .collect();
            keys.push(Key { frame: k.frame, cameras, collage, regions });
        }
        if let Some(c) = a.cameras.iter().find(|c| !a.keys.iter().any(|k| k.frame == c.frame)) {
            anyhow::bail!("--cameras {}={}: frame {} has no --key", c.frame, c.value, c.frame);
        }
        let common = vec![
            "--seed".into(),
            a.seed.to_string(),
            "--fps".into(),
            a.fps.to_string(),
            "--max-depth".into(),
            a.max_depth.to_string(),
        ];
        let mut output_args = common.clone();
        if let Some(sh) = a.shutter {
            output_args.extend(["--shutter".into(), format!("{}..{}", sh.open, sh.close)]);
        }
        if let Some(quality) = a.denoise {
            output_args.push(format!("--denoise={}", quality.name()));
        }
        let mode = a.mode.to_possible_value().map(|v| v.get_name().to_owned()).unwrap_or_default();
        let mut keys_args = vec!["--mode".into(), mode];
        if a.seamless {
            keys_args.push("--seamless".into());
        }
        let res = |r: Resolution| (r.0.x, r.0.y);
        Ok(Shot {
            mcctrace: self.mcctrace()?,
            scene: scene.clone(),
            dir: self.dir.clone(),
            keys,
            frames: FrameSpan { first: frames.first, last: frames.last },
            chunk: a.chunk,
            views: Pass { res: res(a.view_res), spp: a.view_spp, args: common },
            output: Pass { res: res(a.res.unwrap_or(a.view_res)), spp: a.spp, args: output_args },
            keys_args,
            resources: self.resources(),
        })
    }
}

pub fn run(a: FarmArgs) -> anyhow::Result<()> {
    match a.scheduler {
        Scheduler::Slurm(mut s) => {
            if s.submit {
                // The tasks' defaults fitted to the cluster, a flag asking more refused.
                s.job.node = Some(farm::slurm::largest_node(s.job.partition.as_deref(), None)?);
            }
            let (scripts, dir, resources) = match s.job.still()? {
                Some(still) => {
                    let resources: Vec<_> =
                        StillStage::ALL.iter().map(|&st| (st.name(), still.resources(st))).collect();
                    (still.write_slurm()?, still.dir, resources)
                }
                None => {
                    let plan = s.job.shot()?.plan()?;
                    plan.check_inputs()?;
                    let resources: Vec<_> =
                        Stage::ALL.iter().map(|&st| (st.name(), plan.resources(st))).collect();
                    (farm::slurm::write(&plan)?, plan.shot.dir, resources)
                }
            };
            for (stage, r) in resources.iter().filter(|(_, r)| r.was_lowered()) {
                eprintln!("note: {stage}: {}", r.note());
            }
            for (_, path) in &scripts.stages {
                println!("wrote {}", path.display());
            }
            println!("wrote {}", scripts.submit.display());
            if s.submit {
                let jobs = farm::slurm::submit(&scripts, None)?;
                for job in &jobs {
                    println!("{}: job {}", job.stage, job.job_id);
                }
                let ids: Vec<&str> = jobs.iter().map(|j| j.job_id.as_str()).collect();
                println!(
                    "{}",
                    farm::slurm::follow_up(&dir.join("logs").display().to_string(), &ids.join(","))
                );
            } else {
                println!("submit with: bash {}", farm::slurm::submit_hint(&scripts));
            }
        }
        Scheduler::Openjd(job) => {
            let path = match job.still()? {
                Some(still) => still.write_openjd()?,
                None => {
                    let plan = job.shot()?.plan()?;
                    plan.check_inputs()?;
                    farm::openjd::write(&plan)?
                }
            };
            println!("wrote {}", path.display());
            println!("check with: openjd check {0}\nrun locally: openjd run {0}", path.display());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// clap's own consistency checks over the whole command line (ids in conflicts and
    /// requirements, positionals), and both forms of `farm` parse: a still's command is kept
    /// word for word, a shot's flags are refused beside --bands.
    #[test]
    fn both_forms_parse() {
        use clap::CommandFactory;
        crate::Cli::command().debug_assert();
        let parse = |words: &str| crate::Cli::try_parse_from(words.split(' '));
        let still = parse("mcctrace farm slurm --bands 4 --dir d -- render s.gltf --tile 1/2 --out a.exr");
        let Ok(crate::Cli { command: crate::Command::Farm(FarmArgs { scheduler: Scheduler::Slurm(s) }) }) =
            still
        else {
            panic!("{still:?}")
        };
        assert_eq!(s.job.bands, Some(4));
        assert_eq!(s.job.command, ["render", "s.gltf", "--tile", "1/2", "--out", "a.exr"]);
        assert!(s.job.shot.scene.is_none());
        let shot = "mcctrace farm openjd s.gltf --key 0=c.png --cameras 0=a --frames 0..=3 --dir d";
        assert!(parse(shot).is_ok());
        let err = parse("mcctrace farm slurm --bands 4 --spp 3 --dir d -- render s.gltf").unwrap_err();
        assert!(err.to_string().contains("--spp"), "{err}");
        assert!(parse("mcctrace farm slurm --bands 4 --dir d").is_err(), "--bands needs a command");
        assert!(parse("mcctrace farm slurm --dir d").is_err(), "a shot needs its scene");
    }

    /// `--denoise[=QUALITY]` on a shot reaches the output frames' `animate` commands with its
    /// quality, not the source views' (the collages are painted from raw views); refused beside
    /// --bands, where the still's own command carries it to its bands.
    #[test]
    fn denoise_reaches_the_frames_only() {
        let dir = std::env::temp_dir().join(format!("mcctrace-farm-denoise-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let scene = dir.join("s.gltf");
        let collage = dir.join("c.png");
        std::fs::write(&scene, b"{}").unwrap();
        std::fs::write(&collage, b"").unwrap();
        let words = format!(
            "mcctrace farm openjd {} --key 0={} --cameras 0=a --frames 0..=3 --dir {} --denoise=balanced",
            scene.display(),
            collage.display(),
            dir.display()
        );
        let cli = crate::Cli::try_parse_from(words.split(' ')).unwrap();
        let crate::Command::Farm(FarmArgs { scheduler: Scheduler::Openjd(job) }) = cli.command else {
            panic!()
        };
        let shot = job.shot().unwrap();
        assert!(shot.output.args.contains(&"--denoise=balanced".to_owned()), "{:?}", shot.output.args);
        assert!(!shot.views.args.iter().any(|a| a.starts_with("--denoise")), "{:?}", shot.views.args);
        let err = crate::Cli::try_parse_from(
            "mcctrace farm slurm --bands 4 --denoise --dir d -- render s.gltf".split(' '),
        )
        .unwrap_err();
        assert!(err.to_string().contains("--denoise"), "{err}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn memory_and_time_limits() {
        assert_eq!(mem_mib("4096"), Ok(4096));
        assert_eq!(mem_mib("4G"), Ok(4096));
        assert_eq!(mem_mib("512m"), Ok(512));
        assert_eq!(mem_mib("1500K"), Ok(2));
        assert!(mem_mib("4X").unwrap_err().contains("unknown unit"));
        assert!(mem_mib("G").is_err());
        assert_eq!(minutes("90"), Ok(90));
        assert_eq!(minutes("1:30:00"), Ok(90));
        assert_eq!(minutes("0:00:30"), Ok(1));
        assert_eq!(minutes("2-0:00:00"), Ok(2880));
        assert_eq!(minutes("1-2"), Ok(1560));
        assert!(minutes("1:30").is_err() && minutes("x").is_err() && minutes("").is_err());
    }
}
