//! The shot as an Open Job Description job template (docs/farm.md, "Schedulers";
//! `jobtemplate-2023-09`, the format of AWS Deadline Cloud, run anywhere with `openjd run`): the
//! same four stages as steps, each depending on the one before; the views as one task per key
//! frame and camera (three task parameters zipped together), the frames as a parameter space
//! over chunk starts, `FirstFrame-LastFrame:ChunkSize`, from job parameters a user may change at
//! submission. Every task is safe to retry: outputs are written atomically and finished frames
//! are skipped.

use crate::quote::{sh, wrap};
use crate::shot::{Plan, Stage, Word};
use crate::yaml::{Node, document, s};
use crate::{Result, write_file};
use std::path::PathBuf;

/// The template's file name in the shot folder.
pub const TEMPLATE_NAME: &str = "openjd-template.yaml";

fn step_name(stage: Stage) -> &'static str {
    match stage {
        Stage::Views => "Views",
        Stage::Keys => "Keys",
        Stage::Frames => "Frames",
        Stage::Check => "Check",
    }
}

const SHOT_FRAMES: &str = "{{Param.FirstFrame}}..={{Param.LastFrame}}";

/// A command word as a template string.
fn arg(w: &Word) -> String {
    match w {
        Word::Text(t) => t.clone(),
        Word::KeyFrame => "{{Task.Param.KeyFrame}}".into(),
        Word::Camera => "{{Task.Param.Camera}}".into(),
        Word::ViewId => "{{Task.Param.ViewId}}".into(),
        Word::Frames => "$first..=$last".into(),
        Word::ShotFrames => SHOT_FRAMES.into(),
    }
}

fn param(name: &str, kind: &str, range: Node) -> Node {
    Node::Map(vec![("name", s(name)), ("type", s(kind)), ("range", range)])
}

/// The bash script of a frame task: its chunk's last frame from the job parameters.
fn frames_script(plan: &Plan) -> String {
    let mut words = vec![sh(&plan.shot.mcctrace.display().to_string())];
    words.extend(plan.command(Stage::Frames).iter().map(|w| match w {
        Word::Frames => r#""$first..=$last""#.to_owned(),
        other => sh(&arg(other)),
    }));
    format!(
        "#!/usr/bin/env bash\n\
         # The frames from this task's chunk start, up to ChunkSize of them, not past LastFrame.\n\
         set -euo pipefail\n\
         first={{{{Task.Param.ChunkStart}}}}\n\
         last=$((first + {{{{Param.ChunkSize}}}} - 1))\n\
         if ((last > {{{{Param.LastFrame}}}})); then last={{{{Param.LastFrame}}}}; fi\n\
         exec {}\n",
        wrap(&words)
    )
}

fn step(plan: &Plan, stage: Stage) -> Node {
    let r = plan.resources(stage);
    let mut entries = vec![("name", s(step_name(stage)))];
    match stage {
        Stage::Views => {
            let ints = |f: &dyn Fn(&crate::ViewTask) -> u32| {
                Node::List(plan.views.iter().map(|v| Node::Int(i64::from(f(v)))).collect())
            };
            let cameras = Node::List(plan.views.iter().map(|v| s(v.camera.clone())).collect());
            entries.push((
                "parameterSpace",
                Node::Map(vec![
                    (
                        "taskParameterDefinitions",
                        Node::List(vec![
                            param("KeyFrame", "INT", ints(&|v| v.frame)),
                            param("Camera", "STRING", cameras),
                            param("ViewId", "INT", ints(&|v| v.id)),
                        ]),
                    ),
                    // Zipped, not crossed: task i takes the i-th value of each.
                    ("combination", s("(KeyFrame, Camera, ViewId)")),
                ]),
            ));
        }
        Stage::Frames => {
            let range = s("{{Param.FirstFrame}}-{{Param.LastFrame}}:{{Param.ChunkSize}}");
            entries.push((
                "parameterSpace",
                Node::Map(vec![(
                    "taskParameterDefinitions",
                    Node::List(vec![param("ChunkStart", "INT", range)]),
                )]),
            ));
        }
        Stage::Keys | Stage::Check => {}
    }
    let (command, args, files) = if stage == Stage::Frames {
        let file = Node::Map(vec![
            ("name", s("Run")),
            ("type", s("TEXT")),
            ("runnable", Node::Bool(true)),
            ("data", Node::Block(frames_script(plan))),
        ]);
        (s("bash"), vec![s("{{Task.File.Run}}")], vec![file])
    } else {
        let args = plan.command(stage).iter().map(|w| s(arg(w))).collect();
        (s(plan.shot.mcctrace.display().to_string()), args, vec![])
    };
    let on_run = Node::Map(vec![
        ("command", command),
        ("args", Node::List(args)),
        ("timeout", Node::Int(i64::from(r.time_minutes) * 60)),
    ]);
    let mut script = vec![("actions", Node::Map(vec![("onRun", on_run)]))];
    if !files.is_empty() {
        script.push(("embeddedFiles", Node::List(files)));
    }
    entries.push(("script", Node::Map(script)));
    let before = Stage::ALL.iter().position(|&x| x == stage).and_then(|i| i.checked_sub(1));
    if let Some(i) = before {
        entries.push((
            "dependencies",
            Node::List(vec![Node::Map(vec![("dependsOn", s(step_name(Stage::ALL[i])))])]),
        ));
    }
    let amount = |name: &str, min: u64| Node::Map(vec![("name", s(name)), ("min", Node::Int(min as i64))]);
    entries.push((
        "hostRequirements",
        Node::Map(vec![(
            "amounts",
            Node::List(vec![
                amount("amount.worker.vcpu", u64::from(r.cpus)),
                amount("amount.worker.memory", r.mem_mib),
            ]),
        )]),
    ));
    Node::Map(entries)
}

/// The job template of the shot, as YAML.
pub fn template(plan: &Plan) -> String {
    let sh = &plan.shot;
    let int = |name: &str, default: u32, min: i64, what: &str| {
        Node::Map(vec![
            ("name", s(name)),
            ("type", s("INT")),
            ("minValue", Node::Int(min)),
            ("default", Node::Int(i64::from(default))),
            ("description", s(what)),
        ])
    };
    let doc = Node::Map(vec![
        ("specificationVersion", s("jobtemplate-2023-09")),
        ("name", s(format!("mcctrace shot {}", sh.dir.display()))),
        (
            "description",
            s("Written by `mcctrace farm openjd`: the source views of every key frame, `keys`, the output \
               frames in chunks, then every frame checked and the preview. Edit freely."),
        ),
        (
            "parameterDefinitions",
            Node::List(vec![
                int("FirstFrame", sh.frames.first, 0, "The shot's first output frame."),
                int("LastFrame", sh.frames.last, 0, "The shot's last output frame."),
                int("ChunkSize", sh.chunk, 1, "Output frames per task."),
            ]),
        ),
        ("steps", Node::List(Stage::ALL.iter().map(|&st| step(plan, st)).collect())),
    ]);
    format!("# mcctrace farm: shot {}\n{}", sh.dir.display(), document(&doc))
}

/// Writes the template into the shot folder; returns its path.
pub fn write(plan: &Plan) -> Result<PathBuf> {
    let path = plan.path(TEMPLATE_NAME);
    write_file(&path, &template(plan), false)?;
    Ok(path)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shot::tests::Fixture;

    #[test]
    fn template_has_the_steps_their_order_and_the_frame_space() {
        let f = Fixture::new("openjd");
        let plan = f.shot.plan().unwrap();
        let t = template(&plan);
        assert!(t.contains("specificationVersion: \"jobtemplate-2023-09\"\n"));
        let steps: Vec<usize> = ["Views", "Keys", "Frames", "Check"]
            .iter()
            .map(|n| t.find(&format!("  - name: \"{n}\"\n")).unwrap_or_else(|| panic!("step {n} in\n{t}")))
            .collect();
        assert!(steps.windows(2).all(|w| w[0] < w[1]));
        for (before, after) in [("Views", 1), ("Keys", 2), ("Frames", 3)] {
            let step = &t[steps[after]..steps.get(after + 1).copied().unwrap_or(t.len())];
            assert!(step.contains(&format!("- dependsOn: \"{before}\"")), "{step}");
        }
        assert!(!t[steps[0]..steps[1]].contains("dependsOn"));
        assert!(t.contains("combination: \"(KeyFrame, Camera, ViewId)\""));
        assert!(t.contains("- \"by the window\""));
        assert!(t.contains("range: \"{{Param.FirstFrame}}-{{Param.LastFrame}}:{{Param.ChunkSize}}\""));
        assert!(t.contains("if ((last > {{Param.LastFrame}})); then last={{Param.LastFrame}}; fi"));
        // The shot folder's space survives as one quoted argument of the chunk script.
        assert!(t.contains(&format!(" '{}/frames' ", plan.shot.dir.display())), "{t}");
        assert!(t.contains(&format!("- \"{}/lens\"", plan.shot.dir.display())));
    }
}
