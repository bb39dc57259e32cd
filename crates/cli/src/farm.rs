//! `mcctrace farm`: a whole MCC shot as render-farm jobs (docs/farm.md, "Schedulers"): the
//! arguments describe the shot as `render`, `keys` and `animate` would take it; the `farm`
//! library writes the Slurm scripts (and submits them with `--submit`) or the Open Job
//! Description template.

use crate::args::{FrameRange, KeyArg, Resolution, Shutter};
use crate::inbetween::ModeArg;
use anyhow::Context;
use clap::{Args, Subcommand, ValueEnum};
use farm::{FrameSpan, Key, Pass, Resources, Shot};
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
    Openjd(ShotArgs),
}

#[derive(Args, Debug)]
struct SlurmArgs {
    #[command(flatten)]
    shot: ShotArgs,
    /// Submit the stages with sbatch (each after the one before) and print their job ids.
    #[arg(long)]
    submit: bool,
}

/// The shot: what `render` (the views), `keys` and `animate` (the frames) would be given.
#[derive(Args, Debug)]
struct ShotArgs {
    /// Scene file (.gltf, .glb, .obj) or a directory of .obj files.
    scene: PathBuf,
    /// A key: FRAME=COLLAGE or FRAME=COLLAGE,REGIONS, as `keys` takes it. Repeat per key.
    #[arg(long = "key", value_name = "FRAME=COLLAGE[,REGIONS]", required = true)]
    keys: Vec<KeyArg>,
    /// The cameras of a key frame's views, in view order (camera01, camera02, …), as
    /// `render --camera` names them: FRAME=CAMERA[,CAMERA…]. One per key.
    #[arg(long = "cameras", value_name = "FRAME=CAMERA[,CAMERA…]", required = true)]
    cameras: Vec<KeyArg>,
    /// The output frames, FIRST..=LAST.
    #[arg(long, value_name = "A..=B")]
    frames: FrameRange,
    /// The shot folder every task shares: views/, lens/, frames/, logs/ and the jobs go here.
    #[arg(long)]
    dir: PathBuf,
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

impl ShotArgs {
    fn shot(&self) -> anyhow::Result<Shot> {
        let mut keys = Vec::new();
        for k in &self.keys {
            let (collage, regions) = crate::keys::split_key(k)?;
            let cameras = self
                .cameras
                .iter()
                .filter(|c| c.frame == k.frame)
                .flat_map(|c| c.value.split(',').map(str::to_owned))
                .collect();
            keys.push(Key { frame: k.frame, cameras, collage, regions });
        }
        if let Some(c) = self.cameras.iter().find(|c| !self.keys.iter().any(|k| k.frame == c.frame)) {
            anyhow::bail!("--cameras {}={}: frame {} has no --key", c.frame, c.value, c.frame);
        }
        let common = vec![
            "--seed".into(),
            self.seed.to_string(),
            "--fps".into(),
            self.fps.to_string(),
            "--max-depth".into(),
            self.max_depth.to_string(),
        ];
        let mut output_args = common.clone();
        if let Some(sh) = self.shutter {
            output_args.extend(["--shutter".into(), format!("{}..{}", sh.open, sh.close)]);
        }
        let mode = self.mode.to_possible_value().map(|v| v.get_name().to_owned()).unwrap_or_default();
        let mut keys_args = vec!["--mode".into(), mode];
        if self.seamless {
            keys_args.push("--seamless".into());
        }
        let res = |r: Resolution| (r.0.x, r.0.y);
        let mcctrace = match &self.mcctrace {
            Some(p) => p.clone(),
            None => {
                std::env::current_exe().context("finding this mcctrace program (give --mcctrace PATH)")?
            }
        };
        Ok(Shot {
            mcctrace,
            scene: self.scene.clone(),
            dir: self.dir.clone(),
            keys,
            frames: FrameSpan { first: self.frames.first, last: self.frames.last },
            chunk: self.chunk,
            views: Pass { res: res(self.view_res), spp: self.view_spp, args: common },
            output: Pass { res: res(self.res.unwrap_or(self.view_res)), spp: self.spp, args: output_args },
            keys_args,
            resources: Resources {
                cpus: self.cpus_per_task,
                mem_mib: self.mem,
                time_minutes: self.time,
                partition: self.partition.clone(),
            },
        })
    }
}

pub fn run(a: FarmArgs) -> anyhow::Result<()> {
    match a.scheduler {
        Scheduler::Slurm(s) => {
            let plan = s.shot.shot()?.plan()?;
            let scripts = farm::slurm::write(&plan)?;
            for (_, path) in &scripts.stages {
                println!("wrote {}", path.display());
            }
            println!("wrote {}", scripts.submit.display());
            if s.submit {
                for job in farm::slurm::submit(&scripts, None)? {
                    println!("{}: job {}", job.stage.name(), job.job_id);
                }
                println!("logs: {}", plan.path("logs").display());
            } else {
                println!("submit with: bash {}", farm::slurm::submit_hint(&scripts));
            }
        }
        Scheduler::Openjd(shot) => {
            let plan = shot.shot()?.plan()?;
            let path = farm::openjd::write(&plan)?;
            println!("wrote {}", path.display());
            println!("check with: openjd check {0}\nrun locally: openjd run {0}", path.display());
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

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
