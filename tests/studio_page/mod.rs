//! The studio's page in a real browser (issue 24, docs/studio.md): `mcctrace studio` on the café,
//! headless Chromium driven through chromedriver paints two strokes with two cameras through real
//! pointer events, and the test checks (a) the canvas under the strokes shows those cameras'
//! views, (b) the pixels between them change as the preview refines, (c) the saved `collage.png`
//! decodes to the strokes' labels, (d) `mcctrace rerender` on the saved project reproduces the
//! page's "render final" bit for bit. Then a camera move through the page's mouse controls.
//! Screenshots and the page's responsiveness record (its long tasks and its own handlers' times
//! over the whole session) go to `target/test-output/studio_page/`.

mod browser;
mod record;
mod server;

use crate::common::external::external;
use crate::common::{Scratch, repo_root};
use browser::Browser;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The collage size: small, so the preview converges quickly on two loaded cores.
const RES: (u32, u32) = (160, 90);
/// The brush diameter in collage pixels.
const BRUSH: f64 = 9.0;
/// A stroke: the camera it paints, and its start and end (collage pixels).
type Stroke = (u32, (f64, f64), (f64, f64));
/// Two horizontal strokes, camera 1 on the left, camera 2 on the right.
const STROKES: [Stroke; 2] = [(1, (16.0, 30.0), (56.0, 30.0)), (2, (104.0, 60.0), (144.0, 60.0))];
/// "Render final" settings: small, so the rerender comparison is quick.
const FINAL: (u32, u32, u32) = (64, 36, 4);
/// Waits for the server's work (previews, save, final render) on a loaded machine.
const PATIENCE: Duration = Duration::from_secs(180);

fn output_dir() -> PathBuf {
    let dir = repo_root().join("target/test-output/studio_page");
    std::fs::create_dir_all(&dir).expect("create the test's output folder");
    dir
}

/// Distance from the pixel centre (x + ½, y + ½) to the segment a–b.
fn distance_to_segment(x: u32, y: u32, a: (f64, f64), b: (f64, f64)) -> f64 {
    let (px, py) = (x as f64 + 0.5, y as f64 + 0.5);
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let t = (((px - a.0) * dx + (py - a.1) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    ((px - a.0 - t * dx).powi(2) + (py - a.1 - t * dy).powi(2)).sqrt()
}

/// The pixels whose centres lie within `radius` of stroke `s`'s path.
fn near_stroke(s: usize, radius: f64) -> Vec<(u32, u32)> {
    let (_, a, b) = STROKES[s];
    (0..RES.1)
        .flat_map(|y| (0..RES.0).map(move |x| (x, y)))
        .filter(|&(x, y)| distance_to_segment(x, y, a, b) <= radius)
        .collect()
}

fn rgb_at(rgba: &[u8], (x, y): (u32, u32)) -> [u8; 3] {
    let i = ((y * RES.0 + x) * 4) as usize;
    [rgba[i], rgba[i + 1], rgba[i + 2]]
}

/// Mean absolute channel difference between the canvas and an image over `pixels`.
fn mean_difference(canvas: &[u8], image: &image::RgbImage, pixels: &[(u32, u32)]) -> f64 {
    let total: u64 = pixels
        .iter()
        .map(|&(x, y)| {
            let c = rgb_at(canvas, (x, y));
            let v = image.get_pixel(x, y).0;
            (0..3).map(|k| c[k].abs_diff(v[k]) as u64).sum::<u64>()
        })
        .sum();
    total as f64 / (3 * pixels.len()) as f64
}

/// Viewport coordinates of collage pixel `p`'s centre on the page's canvas.
async fn viewport_points(b: &Browser, points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    let r = b.js("const r = document.getElementById('overlay').getBoundingClientRect(); return [r.left, r.top, r.width, r.height];", vec![]).await;
    let r: Vec<f64> = r.as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
    let (sx, sy) = (r[2] / RES.0 as f64, r[3] / RES.1 as f64);
    assert!(
        sx >= 2.0 && sy >= 2.0,
        "the canvas should be shown at least 2× so a pointer hits one pixel: {r:?}"
    );
    points.iter().map(|&(x, y)| (r[0] + x * sx, r[1] + y * sy)).collect()
}

/// Paints stroke `s` with its camera: selects the camera in the list, then drags along the path.
async fn paint_stroke(b: &Browser, s: usize) {
    let (camera, a, z) = STROKES[s];
    b.click(&format!("#camera-list li[data-index='{camera}'] .name")).await;
    let steps = 8;
    let path: Vec<(f64, f64)> = (0..=steps)
        .map(|i| i as f64 / steps as f64)
        .map(|t| (a.0 + t * (z.0 - a.0), a.1 + t * (z.1 - a.1)))
        .collect();
    let points = viewport_points(b, &path).await;
    b.drag(&points).await;
}

async fn save_screenshot(b: &Browser, name: &str) {
    let path = output_dir().join(name);
    std::fs::write(&path, b.screenshot().await).expect("write a screenshot");
    println!("screenshot: {}", path.display());
}

/// A lost connection (the socket closed under the page): the status line says so, the page
/// connects again by itself and `hello` brings the session back; everything after this runs on
/// the new socket.
async fn reconnect(b: &Browser) {
    b.js("window.studio.socket.close();", vec![]).await;
    let log = b
        .wait_for(
            "the page connected again",
            "const S = window.studio; return S.reconnects === 1 && S.socket.readyState === 1 && S.state && S.connLog;",
            PATIENCE,
        )
        .await;
    let log: Vec<&str> = log.as_array().unwrap().iter().map(|v| v.as_str().unwrap()).collect();
    assert!(
        log.len() == 3
            && log[0] == "connected"
            && log[1].starts_with("disconnected: trying again")
            && log[2] == "connected",
        "the status line shows the lost connection and the new one: {log:?}"
    );
    let conn = b.js("return document.getElementById('conn').textContent;", vec![]).await;
    assert_eq!(conn, "connected");
}

/// Requests the server refuses are shown to the user, and the page keeps what the server holds:
/// a "render final" larger than 4096 pixels gives its button back; a field of view of 200° leaves
/// the camera as it was.
async fn refused_requests(b: &Browser) {
    let message = "const m = document.getElementById('message'); return m.classList.contains('error') && m.textContent.includes(arguments[0]) && m.textContent;";
    b.type_into("#final-w", "5000").await;
    b.click("#render-final").await;
    let shown =
        b.wait_for_with("the refused final render shown", message, vec!["5000x".into()], PATIENCE).await;
    println!("refused render final: {shown}");
    let enabled = b.js("return !document.getElementById('render-final').disabled;", vec![]).await;
    assert_eq!(enabled, serde_json::Value::Bool(true), "a refused final render gives the button back");

    let fov = "const S = window.studio; return S.state.cameras.find((c) => c.index === S.selected).fov_deg;";
    let before = b.js(fov, vec![]).await;
    b.type_into("#camera-form input[name='fov']", "200").await;
    let shown = b
        .wait_for_with("the refused camera edit shown", message, vec!["fov_deg in (0, 180)".into()], PATIENCE)
        .await;
    println!("refused camera edit: {shown}");
    let form = "return [parseFloat(document.querySelector(\"#camera-form input[name='fov']\").value), arguments[0]];";
    let back = b
        .wait_for_with(
            "the camera form back at the server's field of view",
            &format!("const [v, f] = (() => {{ {form} }})(); return Math.abs(v - f) < 1e-3 && v;"),
            vec![before.clone()],
            PATIENCE,
        )
        .await;
    assert_eq!(b.js(fov, vec![]).await, before, "the refused edit leaves the camera as it was ({back})");
}

/// Orbits camera `camera` by dragging across the canvas in the source view, waits for its new
/// thumbnail and for a preview of the new state, and checks that its pose changed.
async fn move_camera(b: &Browser, camera: u32) {
    let pose = format!("return window.studio.state.cameras.find((c) => c.index === {camera}).eye;");
    let eye = b.js(&pose, vec![]).await;
    let thumb = format!("return window.studio.sources[{camera}] ? window.studio.sources[{camera}].seq : -1;");
    let thumb_seq = b.js(&thumb, vec![]).await.as_i64().unwrap();
    b.click("#views button[data-view='source']").await;
    let path: Vec<(f64, f64)> = (0..=6).map(|i| (60.0 + 6.0 * i as f64, 45.0)).collect();
    let points = viewport_points(b, &path).await;
    b.drag(&points).await;
    // Every edit answered by the server's `state`, which holds the new pose.
    let eye_after = b
        .wait_for(
            "the camera's new pose",
            &format!(
                "const e = (() => {{ {pose} }})(); return window.studio.cameraIds.size === 0 && JSON.stringify(e) !== JSON.stringify({eye}) && e;"
            ),
            PATIENCE,
        )
        .await;
    assert_ne!(eye, eye_after, "the drag orbits camera {camera}");
    b.wait_for(
        "the moved camera's thumbnail",
        &format!("return (() => {{ {thumb} }})() > {thumb_seq};"),
        PATIENCE,
    )
    .await;
    save_screenshot(b, "5-camera-moved.png").await;
    b.click("#views button[data-view='final']").await;
    b.wait_for(
        "a preview of the moved camera",
        "return window.studio.previewSeq >= window.studio.seq;",
        PATIENCE,
    )
    .await;
}

fn read_rgb(path: &Path) -> image::RgbImage {
    image::open(path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgb8()
}

#[test]
fn paint_two_cameras_preview_save_and_render_final() {
    let (Some(chromium), Some(chromedriver)) = (external("chromium"), external("chromedriver")) else {
        return;
    };
    let load_at_start = record::load_average();
    let scratch = Scratch::new("studio-page");
    let studio = server::Studio::start(&scratch, RES);
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().expect("tokio runtime");
    runtime.block_on(async {
        let b = Browser::start(&chromium, &chromedriver, &scratch.path("profile"), (1100, 650)).await;
        b.client.goto(&studio.url).await.expect("open the studio page");
        let thumbs = "return window.studio && window.studio.sources.filter(Boolean).length >= 2";
        b.wait_for("both cameras' thumbnails", thumbs, PATIENCE).await;
        reconnect(&b).await;
        b.type_into("#size", &format!("{BRUSH}")).await;

        // The canvas as first drawn from a preview of both strokes (each stroke is one `paint`
        // message and bumps `seq`), and as last drawn from a more refined one: kept by the page's
        // draw hook, so no refinement step can slip between two of the test's polls.
        let hook = "const S = window.studio; S.snaps = {};
             S.afterDraw = () => {
               const d = S.drawn;
               if (d.mode !== 'final' || d.paints < 2 || d.pending) return;
               const px = () => Array.from(document.getElementById('canvas').getContext('2d').getImageData(0, 0, S.W, S.H).data);
               if (!S.snaps.first) S.snaps.first = { seq: d.seq, spp: d.spp, px: px() };
               else if (d.seq === S.snaps.first.seq && d.spp > S.snaps.first.spp) S.snaps.last = { seq: d.seq, spp: d.spp, px: px() };
               if (d.seq === S.snaps.first.seq) S.snaps['spp' + d.spp] = { seq: d.seq, spp: d.spp, px: px() };
             };";
        b.js(hook, vec![]).await;
        paint_stroke(&b, 0).await;
        paint_stroke(&b, 1).await;
        b.wait_for("a preview of both strokes", "return !!window.studio.snaps.first", PATIENCE).await;
        save_screenshot(&b, "1-strokes-first-preview.png").await;

        // (b) The preview refines while idle: between the strokes the canvas changes.
        b.wait_for("a refined preview", "return !!window.studio.snaps.last", PATIENCE).await;
        let snap = |which: &'static str| {
            let b = &b;
            async move {
                let v = b.js(&format!("const s = window.studio.snaps.{which}; return [s.spp, s.px];"), vec![]).await;
                let px: Vec<u8> = v[1].as_array().unwrap().iter().map(|n| n.as_u64().unwrap() as u8).collect();
                (v[0].as_i64().unwrap(), px)
            }
        };
        let (spp1, first) = snap("first").await;
        let (spp2, later) = snap("last").await;
        let between: Vec<(u32, u32)> = (0..RES.1)
            .flat_map(|y| (0..RES.0).map(move |x| (x, y)))
            .filter(|&(x, y)| (0..2).all(|s| distance_to_segment(x, y, STROKES[s].1, STROKES[s].2) > BRUSH))
            .collect();
        let changed = between.iter().filter(|&&p| rgb_at(&first, p) != rgb_at(&later, p)).count();
        println!("preview {spp1} → {spp2} spp: {changed} of {} pixels between the strokes changed", between.len());
        assert!(changed * 4 >= between.len(), "the preview between the strokes should refine: {changed} of {} changed", between.len());
        let cores: Vec<Vec<(u32, u32)>> = (0..2).map(|s| near_stroke(s, BRUSH / 2.0 - 1.5)).collect();
        save_screenshot(&b, "2-refined-preview.png").await;

        // (c) Save: the project folder as the batch tools read it.
        b.click("#save").await;
        let dir = b.wait_for("the saved message", "return window.studio.savedDir", PATIENCE).await;
        let dir = PathBuf::from(dir.as_str().expect("saved dir"));
        let (collage, _) = mcc::collage::Collage::load(&dir.join("collage.png"), None, Default::default())
            .expect("the saved collage.png decodes");
        assert_eq!((collage.width, collage.height), RES);
        let page_labels = b.js("return Array.from(window.studio.labels);", vec![]).await;
        let page_labels: Vec<u32> = page_labels.as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as u32).collect();
        assert_eq!(collage.ids, page_labels, "the saved collage is the page's label map");
        for (s, &(camera, a, z)) in STROKES.iter().enumerate() {
            // Hard edges: within the brush radius less a pixel every pixel is the camera; beyond
            // it plus a pixel none is; nothing else but the background anywhere.
            for &(x, y) in &near_stroke(s, BRUSH / 2.0 - 1.0) {
                assert_eq!(collage.id(x, y), camera, "pixel ({x}, {y}) under stroke {s}");
            }
            for y in 0..RES.1 {
                for x in 0..RES.0 {
                    if collage.id(x, y) == camera {
                        let d = distance_to_segment(x, y, a, z);
                        assert!(d <= BRUSH / 2.0 + 1.0, "pixel ({x}, {y}) is camera {camera} {d:.1} px from its stroke");
                    }
                }
            }
        }
        assert_eq!(collage.cameras().into_iter().collect::<Vec<_>>(), vec![1, 2]);

        // The refined canvas is the server's preview as it sent it: exactly `mcctrace rerender`
        // of the saved collage at the collage size and the preview's samples (docs/studio.md,
        // "Engine"), no colour management or scaling on the way.
        let preview = studio.rerender(&dir, &scratch, (RES.0, RES.1, spp2 as u32), "preview");
        let canvas = image::RgbImage::from_fn(RES.0, RES.1, |x, y| image::Rgb(rgb_at(&later, (x, y))));
        assert!(canvas == preview, "the canvas at {spp2} spp differs from mcctrace rerender --spp {spp2}");

        // (a) Under each stroke the canvas is that camera's view. While the preview has fewer
        // samples than the views, the server composes painted pixels from the views' samples
        // (docs/studio.md, "Engine"): then the canvas there is the saved view (rendered by the
        // batch `render`'s job at the same samples) bit for bit, in 8-bit sRGB.
        let project: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(dir.join("studio.json")).expect("studio.json"))
                .expect("studio.json parses");
        let view_spp = project["view_spp"].as_u64().expect("studio.json names view_spp");
        let composed = b.js("const s = window.studio.snaps.spp1; return s ? s.px : null;", vec![]).await;
        assert!(view_spp > 1, "the views have more samples than the first preview");
        let composed: Vec<u8> = composed
            .as_array()
            .expect("the page drew the 1-spp preview of both strokes")
            .iter()
            .map(|n| n.as_u64().unwrap() as u8)
            .collect();
        for (s, &(camera, ..)) in STROKES.iter().enumerate() {
            let exr = dir.join(format!("views/frame0000camera{camera:02}.exr"));
            let view = tracer::image_io::read_exr_rgb(&exr).expect("the saved view's EXR");
            let mut differ = 0;
            for &(x, y) in &near_stroke(s, BRUSH / 2.0 - 1.0) {
                let v = view.pixels[(y * RES.0 + x) as usize].to_array().map(tracer::image_io::linear_to_srgb8);
                differ += usize::from(rgb_at(&composed, (x, y)) != v);
            }
            assert_eq!(differ, 0, "stroke {s}: the 1-spp canvas should be camera {camera}'s view samples under the stroke");
        }

        // Later, the rerender has more samples than the views there: still that camera's view: the saved view (rendered by
        // the batch `render`'s job, tagged) matches it there at least twice as well as the other
        // camera's view does. Independent renders with their own noise, so a statistical check.
        for (s, core) in cores.iter().enumerate() {
            let camera = STROKES[s].0;
            let own = read_rgb(&studio.view_png(&dir, camera));
            let other = read_rgb(&studio.view_png(&dir, 3 - camera));
            let (e_own, e_other) = (mean_difference(&later, &own, core), mean_difference(&later, &other, core));
            println!(
                "stroke {s}: canvas vs camera {camera}'s view {e_own:.2}, vs the other camera's {e_other:.2} (mean |Δ| of 255)"
            );
            assert!(2.0 * e_own < e_other, "stroke {s}: the canvas should show camera {camera}'s view");
        }

        // The other views, for the screenshots.
        for view in ["labels", "source", "weights"] {
            b.click(&format!("#views button[data-view='{view}']")).await;
            tokio::time::sleep(Duration::from_millis(1500)).await;
            save_screenshot(&b, &format!("3-view-{view}.png")).await;
        }
        b.click("#views button[data-view='final']").await;

        // (d) "Render final" on the page, then the batch rerender of the saved project.
        b.type_into("#final-w", &FINAL.0.to_string()).await;
        b.type_into("#final-h", &FINAL.1.to_string()).await;
        b.type_into("#final-spp", &FINAL.2.to_string()).await;
        b.click("#render-final").await;
        b.wait_for("the final render", "return window.studio.finalBytes !== null", PATIENCE).await;
        let bar = b.js("const p = document.getElementById('final-progress'); return [p.value, p.max];", vec![]).await;
        assert_eq!(bar[0], bar[1], "the progress bar is full when the final render arrives: {bar}");
        let bytes = b.js("return Array.from(window.studio.finalBytes);", vec![]).await;
        let bytes: Vec<u8> = bytes.as_array().unwrap().iter().map(|v| v.as_u64().unwrap() as u8).collect();
        let page_final = image::load_from_memory(&bytes).expect("the page's final render is a PNG").to_rgb8();
        save_screenshot(&b, "4-final.png").await;
        let exr = b.wait_for("the final render's file", "return window.studio.finalExr", PATIENCE).await;
        let exr = PathBuf::from(exr.as_str().expect("final exr path"));
        let rerendered = studio.rerender(&dir, &scratch, FINAL, "final");
        assert_eq!(page_final.dimensions(), (FINAL.0, FINAL.1));
        assert!(page_final == rerendered, "mcctrace rerender on the saved project differs from the page's final render");
        let batch = tracer::image_io::read_exr_rgb(&scratch.path("final.exr")).expect("rerender's EXR");
        let studio_exr = tracer::image_io::read_exr_rgb(&exr).expect("the studio's final EXR");
        let bits = |i: &tracer::image::RgbImage| i.pixels.iter().flat_map(|p| p.to_array()).map(f32::to_bits).collect::<Vec<_>>();
        assert!(bits(&batch) == bits(&studio_exr), "the studio's final EXR differs from rerender's, bit for bit");

        refused_requests(&b).await;

        // A camera move: in the source view a drag orbits the selected camera (the last stroke's);
        // its pose changes and its thumbnail is rendered again.
        move_camera(&b, STROKES[1].0).await;

        // The page's responsiveness over the whole session. Long tasks count whatever held the
        // main thread (the test's own scripts too) and stretch with the machine's load, so they
        // are reported; what is asserted is that no handler of the page's own code ran over
        // 50 ms (docs/performance.md §1.6).
        let handlers = record::collect(&b, &output_dir().join("page-record.json"), &load_at_start).await;
        assert!(!handlers.is_empty(), "the page times its handlers");
        let over: Vec<String> = handlers
            .iter()
            .filter(|h| h.max_ms > record::HANDLER_LIMIT_MS)
            .map(|h| format!("{} {:.0} ms", h.name, h.max_ms))
            .collect();
        assert!(over.is_empty(), "handlers of the page ran over {} ms: {}", record::HANDLER_LIMIT_MS, over.join(", "));
        b.quit().await;
    });
    drop(studio);
}
