//! A throwaway ray caster for looking at the café (tests only, nothing committed): flattens the
//! scene to world triangles, builds a median-split BVH and renders each camera with textured
//! base colour, a headlight and the pendant spot (with shadows), written to
//! `/tmp/cafe-preview/` as PNG. Also checks that no camera sits inside geometry and that each
//! over-the-shoulder camera sees its subject's eyes.

use super::materials::Mat;
use super::staging::{self, CameraDef};
use super::textures::{self, Texture, encode_png, srgb8};
use super::{Scene, build, masks};
use crate::gltf_writer::look_at_rotation;
use glam::{Affine3A, Vec2, Vec3};
use std::path::Path;

struct Tri {
    p: [Vec3; 3],
    n: [Vec3; 3],
    uv: [Vec2; 3],
    mat: Mat,
    node: String,
}

struct Hit {
    t: f32,
    tri: usize,
    b: Vec2,
}

#[derive(Clone, Copy)]
struct Bounds {
    lo: Vec3,
    hi: Vec3,
}

impl Bounds {
    const EMPTY: Bounds = Bounds { lo: Vec3::INFINITY, hi: Vec3::NEG_INFINITY };
    fn grow(self, p: Vec3) -> Bounds {
        Bounds { lo: self.lo.min(p), hi: self.hi.max(p) }
    }
    fn hit(&self, o: Vec3, inv: Vec3, tmax: f32) -> bool {
        let (a, b) = ((self.lo - o) * inv, (self.hi - o) * inv);
        let (t0, t1) = (a.min(b).max_element().max(0.0), a.max(b).min_element().min(tmax));
        t0 <= t1
    }
}

enum Node {
    Leaf(Bounds, Vec<usize>),
    Inner(Bounds, Box<Node>, Box<Node>),
}

struct World {
    tris: Vec<Tri>,
    root: Node,
}

fn world_matrix(scene: &Scene, n: usize, parent: Affine3A, out: &mut Vec<(usize, Affine3A)>) {
    let node = &scene.nodes[n];
    let m = parent * Affine3A::from_rotation_translation(node.rotation, node.translation);
    out.push((n, m));
    for &c in &node.children {
        world_matrix(scene, c, m, out);
    }
}

fn build_node(tris: &[Tri], mut ids: Vec<usize>) -> Node {
    let bounds = ids.iter().fold(Bounds::EMPTY, |b, &i| tris[i].p.iter().fold(b, |b, &p| b.grow(p)));
    if ids.len() <= 4 {
        return Node::Leaf(bounds, ids);
    }
    let c = |i: usize| (tris[i].p[0] + tris[i].p[1] + tris[i].p[2]) / 3.0;
    let cb = ids.iter().fold(Bounds::EMPTY, |b, &i| b.grow(c(i)));
    let ext = cb.hi - cb.lo;
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    ids.sort_by(|&a, &b| c(a)[axis].total_cmp(&c(b)[axis]));
    let right = ids.split_off(ids.len() / 2);
    Node::Inner(bounds, Box::new(build_node(tris, ids)), Box::new(build_node(tris, right)))
}

impl World {
    fn new(scene: &Scene) -> World {
        let mut mats = vec![];
        for &r in &scene.roots {
            world_matrix(scene, r, Affine3A::IDENTITY, &mut mats);
        }
        let mut tris = vec![];
        for (n, m) in mats {
            let Some(o) = scene.nodes[n].object else { continue };
            for (&mat, mesh) in &scene.objects[o].parts {
                let mesh = mesh.clone().transformed(m);
                for t in mesh.indices.chunks_exact(3) {
                    let ix = [t[0], t[1], t[2]].map(|i| i as usize);
                    tris.push(Tri {
                        p: ix.map(|i| mesh.positions[i]),
                        n: ix.map(|i| mesh.normals[i]),
                        uv: ix.map(|i| mesh.uvs[i]),
                        mat,
                        node: scene.nodes[n].name.clone(),
                    });
                }
            }
        }
        let root = build_node(&tris, (0..tris.len()).collect());
        World { tris, root }
    }

    fn intersect(&self, o: Vec3, d: Vec3, tmax: f32) -> Option<Hit> {
        let inv = d.recip();
        let mut best: Option<Hit> = None;
        let mut stack = vec![&self.root];
        while let Some(node) = stack.pop() {
            let limit = best.as_ref().map_or(tmax, |h| h.t);
            match node {
                Node::Leaf(b, ids) if b.hit(o, inv, limit) => {
                    for &i in ids {
                        let [a, b1, c] = self.tris[i].p;
                        let (e1, e2) = (b1 - a, c - a);
                        let pv = d.cross(e2);
                        let det = e1.dot(pv);
                        if det.abs() < 1e-12 {
                            continue;
                        }
                        let tv = o - a;
                        let u = tv.dot(pv) / det;
                        let qv = tv.cross(e1);
                        let v = d.dot(qv) / det;
                        let t = e2.dot(qv) / det;
                        if u >= 0.0
                            && v >= 0.0
                            && u + v <= 1.0
                            && t > 1e-4
                            && t < best.as_ref().map_or(tmax, |h| h.t)
                        {
                            best = Some(Hit { t, tri: i, b: Vec2::new(u, v) });
                        }
                    }
                }
                Node::Inner(b, l, r) if b.hit(o, inv, limit) => {
                    stack.push(l);
                    stack.push(r);
                }
                _ => {}
            }
        }
        best
    }
}

/// The camera ray through film position (x, y) of a w × h image.
fn camera_ray(cam: &CameraDef, w: u32, h: u32, x: f32, y: f32) -> Vec3 {
    let q = look_at_rotation(cam.eye, cam.target, Vec3::Y);
    let tan = (cam.yfov_deg.to_radians() / 2.0).tan();
    let aspect = w as f32 / h as f32;
    let px = (2.0 * x / w as f32 - 1.0) * tan * aspect;
    let py = (1.0 - 2.0 * y / h as f32) * tan;
    (q * Vec3::new(px, py, -1.0)).normalize()
}

/// Where world point `p` lands on camera `cam`'s w × h film.
fn project(cam: &CameraDef, w: u32, h: u32, p: Vec3) -> Vec2 {
    let q = look_at_rotation(cam.eye, cam.target, Vec3::Y);
    let local = q.inverse() * (p - cam.eye);
    let tan = (cam.yfov_deg.to_radians() / 2.0).tan();
    let aspect = w as f32 / h as f32;
    let (px, py) = (local.x / -local.z / (tan * aspect), local.y / -local.z / tan);
    Vec2::new((px + 1.0) * 0.5 * w as f32, (1.0 - py) * 0.5 * h as f32)
}

fn sample(t: &Texture, uv: Vec2) -> Vec3 {
    let (i, j) = (
        ((uv.x.rem_euclid(1.0) * t.width as f32) as u32).min(t.width - 1),
        ((uv.y.rem_euclid(1.0) * t.height as f32) as u32).min(t.height - 1),
    );
    let k = ((j * t.width + i) * 3) as usize;
    Vec3::from_array([t.rgb[k], t.rgb[k + 1], t.rgb[k + 2]].map(|c| (f32::from(c) / 255.0).powf(2.2)))
}

fn shade(world: &World, textures: &[Texture], eye: Vec3, d: Vec3) -> Vec3 {
    let Some(hit) = world.intersect(eye, d, 1e9) else { return Vec3::new(1.0, 0.0, 1.0) };
    let tri = &world.tris[hit.tri];
    let w = Vec3::new(1.0 - hit.b.x - hit.b.y, hit.b.x, hit.b.y);
    let n = (tri.n[0] * w.x + tri.n[1] * w.y + tri.n[2] * w.z).normalize();
    let uv = tri.uv[0] * w.x + tri.uv[1] * w.y + tri.uv[2] * w.z;
    let p = eye + d * hit.t;
    if let Some(e) = tri.mat.emission() {
        return Vec3::from_array(e.map(|v| v as f32)) * 0.25;
    }
    let base = Vec3::from_array(tri.mat.base_color().map(|v| v as f32));
    let tex = match tri.mat {
        Mat::Wood | Mat::WoodDark => sample(&textures[0], uv),
        Mat::FloorTiles => sample(&textures[1], uv),
        Mat::SweaterA => sample(&textures[3], uv),
        Mat::DressB => sample(&textures[4], uv),
        Mat::Painting => sample(&textures[6], uv),
        _ => Vec3::ONE,
    };
    let albedo = if tri.mat == Mat::Glass { Vec3::splat(0.6) } else { base * tex };
    let facing = n.dot(-d);
    // Back faces show red: a camera or a surface turned the wrong way.
    if facing < -0.2 && tri.mat != Mat::Glass {
        return Vec3::new(0.8, 0.0, 0.0);
    }
    let head = 0.45 * facing.abs();
    let spot = staging::group_to_world().transform_point3(staging::SPOT_POSITION);
    let to_l = spot - p;
    let dist = to_l.length();
    let l = to_l / dist;
    let cos_spot = (-l).dot(Vec3::NEG_Y);
    let mut direct = 0.0;
    if cos_spot > (staging::SPOT_OUTER as f32).cos()
        && n.dot(l) > 0.0
        && world.intersect(p + n * 1e-3, l, dist - 1e-3).is_none()
    {
        direct = 2.5 * n.dot(l) / (dist * dist);
    }
    albedo * (0.15 + head + direct)
}

fn render(world: &World, textures: &[Texture], cam: &CameraDef, w: u32, h: u32) -> Vec<Vec3> {
    let mut out = vec![];
    for j in 0..h {
        for i in 0..w {
            let d = camera_ray(cam, w, h, i as f32 + 0.5, j as f32 + 0.5);
            out.push(shade(world, textures, cam.eye, d));
        }
    }
    out
}

fn save(path: &Path, w: u32, h: u32, px: &[Vec3]) {
    let rgb: Vec<u8> = px.iter().flat_map(|&c| srgb8(c)).collect();
    std::fs::write(path, encode_png(w, h, &rgb).unwrap()).unwrap();
}

/// The eye spheres' centres of figure `b` (or A), world coordinates.
fn eyes(figure_b: bool) -> [Vec3; 2] {
    let (at, turn) = staging::seat(figure_b);
    let m = staging::group_to_world() * Affine3A::from_rotation_translation(turn, at);
    let h = staging::HEAD_CENTER;
    [-1.0, 1.0].map(|s| m.transform_point3(h + Vec3::new(0.03 * s, -0.005, 0.086)))
}

#[test]
fn cameras_see_their_subjects_from_outside_geometry() {
    let world = World::new(&build());
    for cam in staging::cameras() {
        // From outside every closed object, each first hit is a front face.
        for d in [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z] {
            let hit = world.intersect(cam.eye, d, 1e9).expect("a closed room");
            let t = &world.tris[hit.tri];
            let n = t.n[0] + t.n[1] + t.n[2];
            assert!(
                n.dot(d) < 0.0 || t.mat == Mat::Glass,
                "{}: looking {d} hits the back of {} ({:?})",
                cam.name,
                t.node,
                t.mat
            );
        }
        // No pixel shows the back of a surface (an open mesh or a normal turned the wrong way).
        let (w, h) = (masks::WIDTH, masks::HEIGHT);
        let mut back = vec![];
        for j in 0..h {
            for i in 0..w {
                let d = camera_ray(&cam, w, h, i as f32 + 0.5, j as f32 + 0.5);
                let Some(hit) = world.intersect(cam.eye, d, 1e9) else {
                    panic!("{}: pixel ({i}, {j}) sees nothing", cam.name)
                };
                let t = &world.tris[hit.tri];
                let b = Vec3::new(1.0 - hit.b.x - hit.b.y, hit.b.x, hit.b.y);
                let n = t.n[0] * b.x + t.n[1] * b.y + t.n[2] * b.z;
                if n.dot(d) > 0.2 * n.length() && t.mat != Mat::Glass {
                    back.push((i, j, t.node.clone(), t.mat));
                }
            }
        }
        assert!(
            back.len() < 20,
            "{}: {} pixels see back faces, e.g. {:?}",
            cam.name,
            back.len(),
            &back[..back.len().min(5)]
        );
        let subject = match cam.name {
            "left" => Some((true, "figure_b")),
            "right" => Some((false, "figure_a")),
            _ => None,
        };
        if let Some((b, name)) = subject {
            for e in eyes(b) {
                let d = (e - cam.eye).normalize();
                let hit = world.intersect(cam.eye, d, 1e9).unwrap();
                let t = &world.tris[hit.tri];
                assert_eq!(
                    (t.node.as_str(), t.mat),
                    (name, Mat::Eye),
                    "{} does not see {name}'s eye",
                    cam.name
                );
                let f = project(&cam, masks::WIDTH, masks::HEIGHT, e);
                eprintln!("{}: {name}'s eye at pixel {f}", cam.name);
            }
        }
    }
}

/// Renders every camera and the collage made with the label image to /tmp/cafe-preview/.
/// A close look at one spot from `eye`.
#[test]
#[ignore = "writes preview images; run by hand"]
fn preview_closeups() {
    let dir = Path::new("/tmp/cafe-preview");
    std::fs::create_dir_all(dir).unwrap();
    let world = World::new(&build());
    let textures = textures::all();
    let g = staging::group_to_world();
    let shots = [
        (
            "pendant",
            g.transform_point3(Vec3::new(-0.9, 1.7, -0.9)),
            g.transform_point3(Vec3::new(0.0, 2.2, 0.0)),
            30.0,
        ),
        (
            "table",
            g.transform_point3(Vec3::new(-0.3, 1.25, -0.75)),
            g.transform_point3(Vec3::new(0.0, 0.78, 0.0)),
            45.0,
        ),
        (
            "face_b",
            g.transform_point3(Vec3::new(0.2, 1.35, -0.3)),
            g.transform_point3(staging::face(true)),
            30.0,
        ),
        (
            "face_a",
            g.transform_point3(Vec3::new(-0.2, 1.35, -0.3)),
            g.transform_point3(staging::face(false)),
            30.0,
        ),
        ("window", Vec3::new(1.0, 1.5, 0.0), Vec3::new(4.0, 1.6, -0.3), 60.0),
    ];
    for (name, eye, target, fov) in shots {
        let cam = CameraDef { name, eye, target, yfov_deg: fov };
        let px = render(&world, &textures, &cam, 480, 270);
        save(&dir.join(format!("closeup-{name}.png")), 480, 270, &px);
    }
}

#[test]
#[ignore = "writes preview images; run by hand"]
fn preview_images() {
    let dir = Path::new("/tmp/cafe-preview");
    std::fs::create_dir_all(dir).unwrap();
    let scene = build();
    eprintln!("{} triangles", scene.rendered_triangles());
    let world = World::new(&scene);
    let textures = textures::all();
    let (w, h) = (masks::WIDTH, masks::HEIGHT);
    let mut views = vec![];
    for cam in staging::cameras() {
        let px = render(&world, &textures, &cam, w, h);
        save(&dir.join(format!("{}.png", cam.name)), w, h, &px);
        views.push(px);
    }
    let collage: Vec<Vec3> = (0..h * w)
        .map(|k| match masks::label(k % w, k / w) {
            masks::CAMERA_1 => views[0][k as usize],
            masks::CAMERA_2 => views[1][k as usize],
            _ => Vec3::ZERO,
        })
        .collect();
    save(&dir.join("collage.png"), w, h, &collage);
}

#[test]
#[ignore = "prints statistics"]
fn triangle_budget() {
    let s = build();
    for o in &s.objects {
        let parts: Vec<String> =
            o.parts.iter().map(|(m, p)| format!("{m:?} {}", p.triangle_count())).collect();
        eprintln!("{:>14} {:>7}  {}", o.name, o.triangle_count(), parts.join(", "));
    }
    eprintln!("stored {}, rendered {}", s.stored_triangles(), s.rendered_triangles());
    for c in staging::cameras() {
        eprintln!("camera {}: eye {:.3} target {:.3} yfov {}", c.name, c.eye, c.target, c.yfov_deg);
    }
    let g = staging::group_to_world();
    for b in [false, true] {
        eprintln!("face {}: {:.3}", if b { "B" } else { "A" }, g.transform_point3(staging::face(b)));
    }
}
