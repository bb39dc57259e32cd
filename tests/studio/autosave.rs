//! Ctrl-C with unsaved changes (issue 41, item 14; docs/studio.md, "Autosave"): `mcctrace
//! studio` run as its own process keeps them in `PROJECT.autosave/` and says so; the next studio
//! on the project offers them to the page, which restores or discards them. Nothing unsaved:
//! nothing kept, and it says that.

use super::{Client, Msg, RES, SETTINGS, decode, scene, scratch};
use serde_json::json;
use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

/// Carries the arguments of [`studio_cli_process`].
const ARGS_VAR: &str = "MCCTRACE_STUDIO_AUTOSAVE_ARGS";

/// `mcctrace studio` as a process of its own, for the test below (ignored: not a test itself).
#[test]
#[ignore = "the studio process of the autosave test, started by it"]
fn studio_cli_process() {
    let Ok(args) = std::env::var(ARGS_VAR) else { return };
    let code = mcctrace_cli::main_with_args(std::iter::once("mcctrace").chain(args.lines()));
    std::process::exit(if code == std::process::ExitCode::SUCCESS { 0 } else { 1 });
}

/// Starts `mcctrace studio` on the Cornell box saving to `project`; its page URL, the process
/// and the lines it prints.
fn start_cli(project: &Path) -> (String, std::process::Child, std::sync::mpsc::Receiver<String>) {
    let args = [
        "studio".to_owned(),
        scene().display().to_string(),
        "--res".into(),
        format!("{}x{}", RES[0], RES[1]),
        "--project".into(),
        project.display().to_string(),
    ];
    let mut child = Command::new(std::env::current_exe().unwrap())
        .args(["--ignored", "--exact", "studio::autosave::studio_cli_process", "--nocapture", "--quiet"])
        .env(ARGS_VAR, args.join("\n"))
        .stdout(Stdio::piped())
        .spawn()
        .expect("start mcctrace studio");
    let (tx, rx) = std::sync::mpsc::channel();
    let stdout = child.stdout.take().unwrap();
    std::thread::spawn(move || {
        for line in BufReader::new(stdout).lines().map_while(Result::ok) {
            let _ = tx.send(line);
        }
    });
    let url = loop {
        let line = rx.recv_timeout(Duration::from_secs(120)).expect("mcctrace studio printed its URL");
        if let Some(url) = line.strip_prefix("studio: ").filter(|u| u.starts_with("http://")) {
            break url.to_owned();
        }
    };
    (url, child, rx)
}

/// Sends Ctrl-C (SIGINT) to the studio and returns what it printed until it ended.
fn interrupt(mut child: std::process::Child, lines: std::sync::mpsc::Receiver<String>) -> String {
    let status = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
    assert!(status.success());
    let status = child.wait().unwrap();
    assert!(status.success(), "mcctrace studio ended with {status} on Ctrl-C");
    lines.try_iter().collect::<Vec<_>>().join("\n")
}

#[tokio::test(flavor = "multi_thread", worker_threads = 2)]
async fn ctrl_c_keeps_unsaved_changes_and_the_next_studio_offers_them() {
    let dir = scratch("autosave");
    let project = dir.join("proj");
    let kept = dir.join("proj.autosave");

    // Nothing unsaved: nothing kept, and it says so.
    let (url, child, lines) = start_cli(&project);
    Client::connect_url(&url).await.hello().await;
    let said = interrupt(child, lines);
    assert!(said.contains("no unsaved changes"), "{said}");
    assert!(!kept.exists());

    // A stroke, then Ctrl-C: kept beside the project, never in it (nothing was saved there).
    let (url, child, lines) = start_cli(&project);
    let mut client = Client::connect_url(&url).await;
    client.hello().await;
    let painted: Vec<u8> = (0..RES[0] * RES[1]).map(|p| if p % RES[0] < 9 { 1 } else { 0 }).collect();
    client.paint([0, 0, RES[0], RES[1]], &painted).await;
    let said = interrupt(child, lines);
    assert!(said.contains(&format!("unsaved changes kept in {}", kept.display())), "{said}");
    assert!(kept.join("studio.json").is_file() && !project.join("studio.json").exists());

    // The next studio on the project offers them; discarding removes them.
    let open = || {
        let config = ::studio::Config {
            res: Some(RES),
            engine: SETTINGS,
            ..::studio::Config::new(Some(scene()), project.clone())
        };
        ::studio::serve(config).unwrap()
    };
    let running = open();
    let mut client = Client::connect(&running).await;
    client.send(json!({"type": "hello"})).await;
    let Msg::Json(labels) = client.until(|m| m.kind() == "labels").await else { unreachable!() };
    assert!(decode(&labels["data"]).iter().all(|&l| l == 0), "not restored before the answer");
    let Msg::Json(offer) = client.until(|m| m.kind() == "autosave").await else { unreachable!() };
    assert_eq!(offer["dir"], json!(kept), "{offer}");
    client.send(json!({"type": "autosave", "restore": true})).await;
    let Msg::Json(labels) =
        client.until(|m| matches!(m, Msg::Json(v) if v["type"] == "labels" && v["layer"] == "labels")).await
    else {
        unreachable!()
    };
    assert_eq!(decode(&labels["data"]), painted, "restored");
    let Msg::Json(answered) = client.until(|m| m.kind() == "autosave").await else { unreachable!() };
    assert_eq!(answered["dir"], json!(null), "every tab is told the offer is answered");
    // Restored changes are unsaved in the project: stopping keeps them again.
    assert_eq!(running.autosave().unwrap(), Some(kept.clone()));
    drop(running);

    let running = open();
    let mut client = Client::connect(&running).await;
    client.send(json!({"type": "hello"})).await;
    client.until(|m| m.kind() == "autosave").await;
    client.send(json!({"type": "autosave", "restore": false})).await;
    let Msg::Json(answered) = client.until(|m| m.kind() == "autosave").await else { unreachable!() };
    assert_eq!(answered["dir"], json!(null));
    assert!(!kept.exists(), "discarded");
    assert_eq!(running.autosave().unwrap(), None, "nothing unsaved");
    drop(running);
    std::fs::remove_dir_all(&dir).unwrap();
}
