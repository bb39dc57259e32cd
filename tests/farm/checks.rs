//! What `mcctrace farm` knows before it writes a job (issue 41, items 5–7): a shot that could
//! only fail on the farm is refused with the flag to fix; on `--submit` the tasks are fitted to
//! the cluster's nodes (or refused when a flag asks more than any node has), and without it the
//! scripts say what they assume; after a submission, and in `submit.sh`, the user is told where
//! the logs are and how to see what happened to a job that vanished.

use super::cluster::Cluster;
use super::{CAFE, wrapper};
use crate::common::{Scratch, mcctrace, repo_root};
use crate::layers::{rezip, unzip};
use std::path::Path;

/// Renders the café's `left` and `right` at `res` as a layered collage `key.ora` (the views
/// themselves, unedited: the top one takes every pixel).
fn layered_key(dir: &Scratch, res: &str) {
    let scene = repo_root().join(CAFE).display().to_string();
    let (ora, views) = (dir.s("key.ora"), dir.s("local-views"));
    mcctrace(&[
        "render",
        &scene,
        "--camera",
        "left",
        "--camera",
        "right",
        "--frame",
        "0",
        "--res",
        res,
        "--spp",
        "1",
        "--max-depth",
        "1",
        "--layers",
        &ora,
        "--quiet",
        "--out",
        &views,
    ])
    .unwrap();
}

/// `farm SCHEDULER` of a two-frame shot keyed at frame 0 on `collage`, views at `view_res`, jobs
/// into `dir/name`, and `more` flags.
fn farm_args(
    scheduler: &str,
    dir: &Scratch,
    name: &str,
    collage: &str,
    cameras: &str,
    more: &[&str],
) -> Vec<String> {
    let scene = repo_root().join(CAFE).display().to_string();
    let mut a: Vec<String> = ["farm", scheduler, &scene, "--key", &format!("0={}", dir.s(collage))]
        .into_iter()
        .map(String::from)
        .collect();
    let cameras = format!("0={cameras}");
    let rest =
        ["--cameras", &cameras, "--frames", "0..=1", "--res", "32x18", "--spp", "1", "--view-spp", "1"];
    a.extend(rest.map(String::from));
    a.extend(["--dir".to_owned(), dir.s(name)]);
    a.extend(more.iter().map(|m| m.to_string()));
    a
}

/// The (stage, job id) pairs `farm slurm --submit` printed.
fn submitted(said: &str) -> Vec<(String, String)> {
    said.lines()
        .filter_map(|l| l.split_once(": job "))
        .map(|(stage, id)| (stage.to_owned(), id.trim().to_owned()))
        .collect()
}

fn run(args: &[String]) -> Result<(), String> {
    mcctrace(&args.iter().map(String::as_str).collect::<Vec<_>>()).map_err(|e| format!("{e:#}"))
}

/// Item 5: a collage of another size than the views, a camera the scene lacks, a layer naming
/// no camera of its key: each refused before any script is written, naming the flag; the shot
/// put right is written.
#[test]
fn farm_refuses_a_shot_that_could_only_fail_on_the_farm() {
    let dir = Scratch::new("farm-checks");
    layered_key(&dir, "64x36");
    for scheduler in ["slurm", "openjd"] {
        // The default --view-res (640x360) against a 64x36 collage.
        let err = run(&farm_args(scheduler, &dir, "a", "key.ora", "left,right", &[])).unwrap_err();
        assert!(
            err.contains("--view-res")
                && err.contains("640x360")
                && err.contains("is 64x36")
                && err.contains("key.ora"),
            "{err}"
        );
        assert!(
            !dir.path("a").join("slurm").exists() && !dir.path("a/openjd-template.yaml").exists(),
            "nothing written"
        );
        // A camera name the scene does not have.
        let err = run(&farm_args(scheduler, &dir, "a", "key.ora", "lef,right", &["--view-res", "64x36"]))
            .unwrap_err();
        assert!(err.contains("--cameras") && err.contains("\"lef\"") && err.contains("'left'"), "{err}");
        assert!(!dir.path("a").exists(), "nothing written");
    }
    // A layer that names no camera of the key, and one whose name is another of its cameras.
    let entries = unzip(&dir.path("key.ora"));
    for (to, said) in
        [("Layer 1", "names no camera"), ("right (camera 1)", "its name says camera 2 (\"right\")")]
    {
        let mut renamed = entries.clone();
        let stack = renamed.iter_mut().find(|(n, _)| n == "stack.xml").unwrap();
        stack.1 = String::from_utf8(stack.1.clone()).unwrap().replace("left (camera 1)", to).into_bytes();
        rezip(&dir.path("renamed.ora"), &renamed);
        let err = run(&farm_args("slurm", &dir, "b", "renamed.ora", "left,right", &["--view-res", "64x36"]))
            .unwrap_err();
        assert!(
            err.contains("--key") && err.contains(&format!("layer \"{to}\"")) && err.contains(said),
            "{err}"
        );
        assert!(!dir.path("b").exists(), "nothing written");
    }
    // Put right, the shot is written (cameras by index too, as `render --camera` takes them).
    run(&farm_args("slurm", &dir, "c", "key.ora", "left,right", &["--view-res", "64x36"])).unwrap();
    assert!(dir.path("c/slurm/submit.sh").is_file());
    run(&farm_args("openjd", &dir, "d", "key.ora", "left,right", &["--view-res", "64x36"])).unwrap();
    assert!(dir.path("d/openjd-template.yaml").is_file());
}

/// The `#SBATCH --cpus-per-task` of a written stage script.
fn cpus_of(script: &Path) -> String {
    let text = std::fs::read_to_string(script).unwrap();
    text.lines().find_map(|l| l.strip_prefix("#SBATCH --cpus-per-task=")).unwrap().to_owned()
}

/// Item 6: views over 256x256 ask 4 CPUs by default. Without --submit the script says so and
/// what a smaller cluster does with it; with --submit on this 2-CPU node they ask 2 and the
/// command says why; a flag asking 4 is refused, naming it.
#[test]
fn submit_fits_the_tasks_to_the_clusters_nodes() {
    let Some(cluster) = Cluster::find() else { return };
    let dir = Scratch::new("farm-fit");
    layered_key(&dir, "384x216");
    let program = wrapper(dir.dir());
    let p = program.display().to_string();
    let base = ["--view-res", "384x216", "--mcctrace", &p];
    run(&farm_args("slurm", &dir, "written", "key.ora", "left,right", &base)).unwrap();
    let views = dir.path("written/slurm/1-views.sbatch");
    assert_eq!(cpus_of(&views), "4");
    let text = std::fs::read_to_string(&views).unwrap();
    assert!(text.contains("# Resources: each task asks 4 CPUs") && text.contains("pending"), "{text}");

    let nodes = String::from_utf8(
        cluster
            .output(Path::new("sinfo"), &["--noheader".into(), "--Node".into(), "--format=%c".into()])
            .stdout,
    )
    .unwrap();
    let most: u32 = nodes.lines().map(|l| l.trim().parse::<u32>().unwrap()).max().unwrap();
    assert!(most < 4, "this test needs a cluster whose nodes have fewer than 4 CPUs (sinfo: {nodes:?})");
    let mut args = farm_args("slurm", &dir, "fitted", "key.ora", "left,right", &base);
    args.push("--submit".into());
    let out = cluster.output(&program, &args);
    let (said, err) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(out.status.success(), "{said}\n{err}");
    cluster.cancel(&submitted(&said));
    assert_eq!(cpus_of(&dir.path("fitted/slurm/1-views.sbatch")), most.to_string());
    assert!(
        err.contains(&format!("note: views: {most} CPUs per task instead of the default 4"))
            && err.contains("(sinfo)"),
        "{err}"
    );
    // Asked for by flag, 4 CPUs are refused before anything is written or submitted.
    let mut args = farm_args("slurm", &dir, "refused", "key.ora", "left,right", &base);
    args.extend(["--cpus-per-task", "4", "--submit"].map(String::from));
    let out = cluster.output(&program, &args);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{err}");
    assert!(err.contains("--cpus-per-task") && err.contains(&format!("has {most} (sinfo)")), "{err}");
    assert!(!dir.path("refused/slurm").exists());
}

/// Item 7: when the views stage fails, Slurm cancels the stages after it and they leave no log.
/// `farm slurm --submit` (and `submit.sh`) say where the logs are and how to see what happened;
/// following that advice finds the failed task's log and the cancelled job's state.
#[test]
fn a_failed_stage_says_where_to_look() {
    let Some(cluster) = Cluster::find() else { return };
    let dir = Scratch::new("farm-failed");
    layered_key(&dir, "64x36");
    let program = wrapper(dir.dir());
    let failing = dir.path("failing-mcctrace");
    std::fs::write(&failing, "#!/bin/sh\necho 'mcctrace: a simulated failure' >&2\nexit 3\n").unwrap();
    use std::os::unix::fs::PermissionsExt;
    std::fs::set_permissions(&failing, std::fs::Permissions::from_mode(0o755)).unwrap();
    let f = failing.display().to_string();
    let mut args =
        farm_args("slurm", &dir, "shot", "key.ora", "left,right", &["--view-res", "64x36", "--mcctrace", &f]);
    args.extend(["--cpus-per-task=1", "--submit"].map(String::from));
    let out = cluster.output(&program, &args);
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{said}\n{}", String::from_utf8_lossy(&out.stderr));
    let jobs = submitted(&said);
    assert_eq!(jobs.len(), 4, "{said}");
    let ids: Vec<&str> = jobs.iter().map(|(_, id)| id.as_str()).collect();
    assert!(said.contains(&format!("logs: {}/ ", dir.path("shot/logs").display())), "{said}");
    assert!(
        said.contains("scontrol show job JOBID") && said.contains(&format!("--jobs={}", ids.join(","))),
        "{said}"
    );
    cluster.wait(&jobs, &dir.path("shot"));
    // What the submission printed (again, from submit.sh's own text, which echoes the same).
    let submit = std::fs::read_to_string(dir.path("shot/slurm/submit.sh")).unwrap();
    assert!(
        submit.contains("scontrol show job") && submit.contains("--jobs=$views,$keys,$frames,$check"),
        "{submit}"
    );
    let logs = dir.path("shot/logs");
    let failed: Vec<String> = std::fs::read_dir(&logs)
        .unwrap()
        .map(|e| std::fs::read_to_string(e.unwrap().path()).unwrap_or_default())
        .collect();
    assert!(failed.iter().any(|l| l.contains("a simulated failure")), "the views' logs: {failed:?}");
    let keys = &jobs[1].1;
    let shown = cluster.show_job(keys);
    assert!(
        shown.contains("JobState=CANCELLED") || shown.contains("DependencyNeverSatisfied"),
        "scontrol show job {keys}: {shown}"
    );
}
