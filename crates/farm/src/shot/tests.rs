//! The shot's checks, its plan's commands, chunks and resources; the fixture the writers'
//! tests share.

use super::*;
use crate::FarmError;

/// A scratch folder with a scene file and two collages (contents do not matter here), and a
/// shot over it: keys at 0 (two cameras) and 11 (two others), frames 0..=11 in chunks of 5.
pub(crate) struct Fixture {
    pub dir: PathBuf,
    pub shot: Shot,
}

impl Fixture {
    pub(crate) fn new(name: &str) -> Self {
        let dir = std::env::temp_dir().join(format!("mcctrace-farm-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        for f in ["scene.gltf", "collage0.png", "collage 11.png", "regions0.png"] {
            std::fs::write(dir.join(f), b"x").unwrap();
        }
        let key = |frame, cameras: &[&str], collage: &str, regions: Option<&str>| Key {
            frame,
            cameras: cameras.iter().map(|c| c.to_string()).collect(),
            collage: dir.join(collage),
            regions: regions.map(|r| dir.join(r)),
        };
        let shot = Shot {
            mcctrace: PathBuf::from("/opt/mcc/bin/mcctrace"),
            scene: dir.join("scene.gltf"),
            dir: dir.join("shot one"),
            // Out of order on purpose: the plan sorts them.
            keys: vec![
                key(11, &["wide", "by the window"], "collage 11.png", None),
                key(0, &["left", "right"], "collage0.png", Some("regions0.png")),
            ],
            frames: FrameSpan { first: 0, last: 11 },
            chunk: 5,
            views: Pass { res: (64, 36), spp: 4, args: vec!["--seed".into(), "3".into()] },
            output: Pass { res: (64, 36), spp: 8, args: vec![] },
            keys_args: vec!["--mode".into(), "smooth".into()],
            resources: Resources::default(),
        };
        Self { dir, shot }
    }
}

impl Drop for Fixture {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

fn text(words: &[Word]) -> Vec<String> {
    words
        .iter()
        .map(|w| match w {
            Word::Text(t) => t.clone(),
            other => format!("<{other:?}>"),
        })
        .collect()
}

#[test]
fn views_follow_the_keys_cameras_in_order() {
    let f = Fixture::new("views");
    let plan = f.shot.plan().unwrap();
    let views: Vec<(u32, &str, u32)> =
        plan.views.iter().map(|v| (v.frame, v.camera.as_str(), v.id)).collect();
    assert_eq!(views, [(0, "left", 1), (0, "right", 2), (11, "wide", 1), (11, "by the window", 2)]);
    let render = text(&plan.command(Stage::Views));
    assert_eq!(render[0], "render");
    assert!(render.windows(2).any(|w| w == ["--camera", "<Camera>"]));
    assert!(render.windows(2).any(|w| w == ["--first-id", "<ViewId>"]));
    assert!(render.windows(2).any(|w| w[0] == "--out" && w[1].ends_with("shot one/views")));
    assert!(render.windows(2).any(|w| w == ["--seed", "3"]));
}

#[test]
fn keys_take_every_collage_and_the_frames_the_whole_shot() {
    let f = Fixture::new("keys");
    let plan = f.shot.plan().unwrap();
    let keys = text(&plan.command(Stage::Keys));
    let given: Vec<&String> = keys.windows(2).filter(|w| w[0] == "--key").map(|w| &w[1]).collect();
    let (c0, r0, c11) =
        (f.dir.join("collage0.png"), f.dir.join("regions0.png"), f.dir.join("collage 11.png"));
    assert_eq!(given, [&format!("0={},{}", c0.display(), r0.display()), &format!("11={}", c11.display())]);
    assert!(keys.windows(2).any(|w| w == ["--frames", "<ShotFrames>"]));
    assert!(keys.windows(2).any(|w| w == ["--res", "64x36"]));
    let frames = text(&plan.command(Stage::Frames));
    assert!(frames.windows(2).any(|w| w == ["--frames", "<Frames>"]));
    assert!(frames.windows(2).any(|w| w == ["--preview", "none"]));
    let check = text(&plan.command(Stage::Check));
    assert!(check.windows(2).any(|w| w == ["--frames", "<ShotFrames>"]));
    assert!(check.contains(&"--check".to_owned()) && !check.contains(&"--preview".to_owned()));
}

#[test]
fn chunks_cover_the_frames_once_when_the_count_does_not_divide() {
    let mut f = Fixture::new("chunks");
    for (first, last, chunk) in [(0, 11, 5), (3, 3, 4), (0, 9, 10), (7, 30, 1), (10, 21, 4)] {
        f.shot.frames = FrameSpan { first, last };
        f.shot.chunk = chunk;
        let plan = f.shot.plan().unwrap();
        let covered: Vec<u32> = plan.chunks.iter().flat_map(|c| c.first..=c.last).collect();
        assert_eq!(covered, (first..=last).collect::<Vec<_>>(), "{first}..={last} by {chunk}");
        assert!(plan.chunks.iter().all(|c| c.len() <= u64::from(chunk) && !c.is_empty()));
        assert_eq!(plan.chunks.len() as u64, (u64::from(last - first) + 1).div_ceil(u64::from(chunk)));
    }
    f.shot.frames = FrameSpan { first: 0, last: 11 };
    f.shot.chunk = 5;
    let spans: Vec<String> = f.shot.plan().unwrap().chunks.iter().map(|c| c.to_string()).collect();
    assert_eq!(spans, ["0..=4", "5..=9", "10..=11"]);
}

#[test]
fn frames_near_the_top_of_the_range_do_not_overflow() {
    let mut f = Fixture::new("top");
    f.shot.frames = FrameSpan { first: u32::MAX - 2, last: u32::MAX };
    f.shot.chunk = 2;
    let spans: Vec<String> = f.shot.plan().unwrap().chunks.iter().map(|c| c.to_string()).collect();
    assert_eq!(spans, [format!("{}..={}", u32::MAX - 2, u32::MAX - 1), format!("{0}..={0}", u32::MAX)]);
}

#[test]
fn resources_default_from_the_render_settings_and_yield_to_the_shot() {
    let mut f = Fixture::new("resources");
    let plan = f.shot.plan().unwrap();
    let small = plan.resources(Stage::Frames);
    assert_eq!((small.cpus, small.time_minutes), (1, LEAST_MINUTES as u32));
    f.shot.output = Pass { res: (1920, 1080), spp: 1024, args: vec![] };
    f.shot.chunk = 10;
    let plan = f.shot.plan().unwrap();
    let big = plan.resources(Stage::Frames);
    assert_eq!(big.cpus, 4);
    // 1920 × 1080 × 1024 × 10 samples at 100k per CPU-second on 4 CPUs, times 4.
    let samples = 1920 * 1080 * 1024 * 10u64;
    assert_eq!(u64::from(big.time_minutes), 4 * (samples / 400_000).div_ceil(60));
    assert!(big.mem_mib > small.mem_mib && big.mem_mib >= 1920 * 1080 * 512 / (1 << 20));
    f.shot.resources =
        Resources { cpus: Some(2), mem_mib: Some(300), time_minutes: Some(7), partition: None, node: None };
    let given = f.shot.plan().unwrap().resources(Stage::Frames);
    assert_eq!(
        given,
        StageResources { cpus: 2, mem_mib: 300, time_minutes: 7, node: None, lowered: (None, None) }
    );
}

#[track_caller]
fn refused(shot: &Shot, flag: &str, says: &str) {
    match shot.plan() {
        Err(FarmError::Shot { flag: f, message }) => {
            assert_eq!(f, flag, "{message}");
            assert!(message.contains(says), "{flag}: {message}");
            assert!(FarmError::Shot { flag: f, message }.to_string().starts_with(flag));
        }
        other => panic!("expected an error naming {flag}, got {other:?}"),
    }
}

#[test]
fn bad_shots_are_refused_naming_the_flag() {
    let f = Fixture::new("bad");
    let with = |edit: &dyn Fn(&mut Shot)| {
        let mut s = f.shot.clone();
        edit(&mut s);
        s
    };
    refused(&with(&|s| s.keys.clear()), "--key", "at least one key");
    refused(&with(&|s| s.keys[1].frame = 11), "--key", "frame 11 has two keys");
    refused(&with(&|s| s.keys[0].cameras.clear()), "--cameras", "--cameras 11=");
    refused(&with(&|s| s.keys[0].cameras[1] = " ".into()), "--cameras", "empty camera");
    refused(&with(&|s| s.chunk = 0), "--chunk", "0 frames per task");
    refused(&with(&|s| s.views.res = (0, 36)), "--view-res", "zero dimension");
    refused(&with(&|s| s.output.spp = 0), "--spp", "0 samples");
    refused(&with(&|s| s.resources.cpus = Some(0)), "--cpus-per-task", "0 CPUs");
    refused(&with(&|s| s.resources.mem_mib = Some(0)), "--mem", "0 MiB");
    refused(&with(&|s| s.resources.time_minutes = Some(0)), "--time", "0 minutes");
    refused(&with(&|s| s.resources.partition = Some("a b".into())), "--partition", "not a partition");
    refused(&with(&|s| s.scene = f.dir.join("missing.gltf")), "SCENE", "missing.gltf: no such file");
    refused(&with(&|s| s.keys[1].collage = f.dir.join("nope.png")), "--key", "key at frame 0: ");
    refused(&with(&|s| s.keys[1].regions = Some(f.dir.join("nope.png"))), "--key", "nope.png is not a file");
}
