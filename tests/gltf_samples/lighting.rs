//! Lighting a model that carries no light, through the command line: `--sky` (a uniform sky,
//! importance-sampled like an environment image) and `--exposure` (stops), both recorded in the
//! EXR header. BoxVertexColors has no light, no camera and no material (glTF's default: a
//! rough white metal, here tinted by its vertex colours).

use super::sample;
use crate::common::{Scratch, mcctrace};
use std::path::Path;
use tracer::image_io::read_exr;

#[test]
fn a_sky_lights_a_model_without_light_and_exposure_doubles_it_per_stop() {
    let dir = Scratch::new("sky-exposure");
    let model = sample("BoxVertexColors").display().to_string();
    let render = |name: &str, extra: &[&str]| {
        let out = dir.s(name);
        let mut args = vec![
            "render",
            &model,
            "--look-from",
            "1.5,1.2,2",
            "--look-at",
            "0,0,0",
            "--res",
            "24x16",
            "--spp",
            "4",
            "--threads",
            "2",
            "-q",
            "--out",
            &out,
        ];
        args.extend(extra);
        mcctrace(&args).unwrap_or_else(|e| panic!("{e:#}"));
        let exr = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.extension().is_some_and(|x| x == "exr"));
        read_exr(Path::new(&exr.expect("an EXR"))).unwrap()
    };
    let dark = render("dark", &[]);
    assert!(dark.rgb.pixels.iter().all(|p| p.max_element() == 0.0), "no light, yet not black");
    let grey = render("grey", &["--sky", "grey"]);
    assert!(grey.rgb.pixels.iter().any(|p| p.max_element() > 0.0), "the sky lights nothing");
    assert_eq!(grey.metadata["mcctrace/sky"], "0.050876,0.050876,0.050876");
    assert!(!grey.metadata.contains_key("mcctrace/exposure"));
    // One stop up is twice the light everywhere; scaling by a power of two is exact in floats,
    // so the pictures agree bit for bit.
    let brighter = render("brighter", &["--sky", "grey", "--exposure", "1"]);
    assert_eq!(brighter.metadata["mcctrace/exposure"], "1");
    for (a, b) in grey.rgb.pixels.iter().zip(&brighter.rgb.pixels) {
        assert_eq!(*a * 2.0, *b);
    }
    // Bad values name the flag.
    let err = mcctrace(&["render", &model, "--sky", "blue", "--out", &dir.s("bad")]).unwrap_err();
    assert!(format!("{err:#}").contains("--sky"), "{err:#}");
    let out = dir.s("bad");
    let err = mcctrace(&[
        "render",
        &model,
        "--look-from",
        "1,1,1",
        "--look-at",
        "0,0,0",
        "--exposure",
        "99",
        "--out",
        &out,
    ])
    .unwrap_err();
    assert!(format!("{err:#}").contains("--exposure 99"), "{err:#}");
}
