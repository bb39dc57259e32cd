//! The stress scene, built in code: one object per material of the tracer (docs/design/tracer.md §3.1,
//! "Integrator"), lit by each light type in turn or all at once, seen through each camera model
//! (docs/design/tracer.md §3.8), and the similarity transform that scales and moves it
//! together with everything whose units are lengths.

use crate::common::{icosphere, look_at};
use glam::{Affine3A, DVec3, Vec2, Vec3, Vec4};
use std::path::PathBuf;
use tracer::camera::{CameraDesc, Projection};
use tracer::material::{AlphaMode, Material, MaterialTextures};
use tracer::scene::{Environment, EnvironmentMap, Mesh, MeshExtras, MeshPart, PunctualLight, Scene};
use tracer::texture::{Filter, Texture, TextureRef};

/// Which lights the stress scene has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lighting {
    /// Emissive triangles only: a one-sided and a double-sided emitter.
    Area,
    /// One point light.
    Point,
    /// One spot light.
    Spot,
    /// One directional light.
    Directional,
    /// A constant environment colour.
    Sky,
    /// An equirectangular environment image with a bright sun (importance-sampled).
    EnvMap,
    /// Everything above at once (the environment image replaces the constant colour).
    All,
}

impl Lighting {
    /// Every single light type.
    pub const EACH: [Lighting; 6] =
        [Self::Area, Self::Point, Self::Spot, Self::Directional, Self::Sky, Self::EnvMap];
}

/// The camera models.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Model {
    Perspective,
    Orthographic,
    ThinLens,
    Fisheye,
    Equirectangular,
}

impl Model {
    /// Every camera model.
    pub const EACH: [Model; 5] =
        [Self::Perspective, Self::Orthographic, Self::ThinLens, Self::Fisheye, Self::Equirectangular];
}

/// The materials of the stress scene, in `Scene::materials` order.
pub mod mat {
    pub const FLOOR: u32 = 0; // Lambert, normal-mapped through explicit vertex tangents
    pub const WALL: u32 = 1; // Lambert
    pub const LAMBERT: u32 = 2; // Lambert sphere with smooth vertex normals
    pub const METAL: u32 = 3; // GGX metal, fairly smooth
    pub const ROUGH: u32 = 4; // rough dielectric: Lambert + GGX specular layer
    pub const GLASS: u32 = 5; // smooth dielectric, transmission 1
    pub const MASKED: u32 = 6; // base-colour texture with alpha cut-outs
    pub const BUMPY: u32 = 7; // normal map, tangents from the texture coordinates
    pub const EMIT_ONE: u32 = 8; // one-sided emitter
    pub const EMIT_TWO: u32 = 9; // double-sided emitter
    pub const COUNT: usize = 10;
}

/// The textures: 0 the masked checker (RGBA), 1 the bump normal map.
pub fn textures() -> Vec<Texture> {
    // 4 × 4 checker: opaque coloured cells and fully transparent ones.
    let checker = (0..16)
        .map(|i| {
            let (x, y) = (i % 4, i / 4);
            if (x + y) % 2 == 0 { Vec4::new(0.9, 0.6, 0.1, 1.0) } else { Vec4::new(0.1, 0.5, 0.9, 0.0) }
        })
        .collect();
    // 8 × 8 tangent-space normals leaning ±0.6 in x and y in a pattern (glTF encoding n/2 + ½).
    let bumps = (0..64)
        .map(|i| {
            let (x, y) = (i % 8, i / 8);
            let lean = |k: i32| if k % 4 < 2 { 0.6 } else { -0.6 };
            let n = Vec3::new(lean(x), lean(y + 1), 1.0).normalize();
            (n * 0.5 + Vec3::splat(0.5)).extend(1.0)
        })
        .collect();
    vec![Texture::new("checker", 4, 4, checker), Texture::new("bumps", 8, 8, bumps)]
}

/// The materials, indexed by [`mat`]; the emitters emit only when `emitters_on`.
pub fn materials(emitters_on: bool) -> Vec<Material> {
    let emission = |e: Vec3| if emitters_on { e } else { Vec3::ZERO };
    let m = |name: &str, base: Vec3| Material::diffuse(name, base);
    let list = vec![
        Material {
            textures: MaterialTextures { normal: Some((TextureRef::new(1), 0.7)), ..Default::default() },
            ..m("floor", Vec3::new(0.6, 0.6, 0.55))
        },
        m("wall", Vec3::new(0.5, 0.4, 0.3)),
        m("lambert", Vec3::new(0.7, 0.2, 0.2)),
        Material { metallic: 1.0, roughness: 0.25, ..m("metal", Vec3::new(0.9, 0.8, 0.5)) },
        Material { specular: 1.0, roughness: 0.6, ..m("rough", Vec3::new(0.2, 0.4, 0.8)) },
        Material { transmission: 1.0, roughness: 0.0, specular: 1.0, ior: 1.5, ..m("glass", Vec3::ONE) },
        Material {
            alpha_mode: AlphaMode::Mask { cutoff: 0.5 },
            textures: MaterialTextures {
                base_color: Some(TextureRef { filter: Filter::Nearest, ..TextureRef::new(0) }),
                ..Default::default()
            },
            ..m("masked", Vec3::ONE)
        },
        Material {
            textures: MaterialTextures { normal: Some((TextureRef::new(1), 1.0)), ..Default::default() },
            ..m("bumpy", Vec3::new(0.3, 0.7, 0.3))
        },
        Material { emission: emission(Vec3::new(6.0, 6.0, 5.0)), ..m("emit-one", Vec3::splat(0.5)) },
        Material {
            emission: emission(Vec3::new(1.0, 2.0, 4.0)),
            emission_two_sided: true,
            ..m("emit-two", Vec3::splat(0.5))
        },
    ];
    assert_eq!(list.len(), mat::COUNT);
    list
}

/// A rectangle centre ± a ± b (its front faces a × b), with
/// texture coordinates (0, 0) at centre − a + b … (1, 1) at centre + a − b.
fn quad(centre: Vec3, a: Vec3, b: Vec3) -> ([Vec3; 4], [Vec2; 4]) {
    let p = [centre - a - b, centre + a - b, centre + a + b, centre - a + b];
    let uv = [Vec2::new(0.0, 1.0), Vec2::new(1.0, 1.0), Vec2::new(1.0, 0.0), Vec2::new(0.0, 0.0)];
    (p, uv)
}

pub fn push_quad(mesh: &mut Mesh, centre: Vec3, a: Vec3, b: Vec3, material: u32, tangents: bool) {
    let (p, uv) = quad(centre, a, b);
    let t = [a.normalize().extend(1.0); 4];
    let extras = MeshExtras { tangents: tangents.then_some(&t[..]), ..Default::default() };
    let part = MeshPart {
        positions: &p,
        normals: None,
        uvs: Some(&uv),
        indices: Some(&[0, 1, 2, 0, 2, 3]),
        material,
    };
    mesh.push_with(part, extras).expect("quad");
}

fn push_sphere(mesh: &mut Mesh, centre: Vec3, radius: f32, material: u32) {
    let (positions, indices) = icosphere(2, centre, radius, false);
    // Exact normals of the sphere (smooth shading), computed before any rounding of positions.
    let normals: Vec<Vec3> = positions.iter().map(|p| (*p - centre).normalize()).collect();
    let part = MeshPart {
        positions: &positions,
        normals: Some(&normals),
        uvs: None,
        indices: Some(&indices),
        material,
    };
    mesh.push(part).expect("sphere");
}

/// The stress scene at unit scale, lit by `lighting`.
pub fn showcase(lighting: Lighting) -> Scene {
    use mat::*;
    let mut mesh = Mesh::default();
    // Floor (normal-mapped, explicit tangents) and back wall.
    push_quad(&mut mesh, Vec3::new(0.0, 0.0, -0.75), Vec3::X * 2.5, Vec3::Z * -2.25, FLOOR, true);
    push_quad(&mut mesh, Vec3::new(0.0, 1.5, -3.0), Vec3::X * 2.5, Vec3::Y * 1.5, WALL, false);
    push_sphere(&mut mesh, Vec3::new(-1.3, 0.5, -1.2), 0.5, LAMBERT);
    push_sphere(&mut mesh, Vec3::new(0.0, 0.55, -1.8), 0.55, METAL);
    push_sphere(&mut mesh, Vec3::new(1.3, 0.5, -1.2), 0.5, ROUGH);
    push_sphere(&mut mesh, Vec3::new(0.5, 0.35, 0.0), 0.35, GLASS);
    // The masked checker faces the camera (+Z); the bumpy quad too, turned a little.
    push_quad(&mut mesh, Vec3::new(-0.7, 0.6, -0.2), Vec3::X * 0.45, Vec3::Y * 0.6, MASKED, false);
    let turn = Vec3::new(0.9, 0.0, 0.45).normalize();
    push_quad(&mut mesh, Vec3::new(1.55, 0.65, -0.2), turn * 0.45, Vec3::Y * 0.6, BUMPY, false);
    // One-sided emitter under the "ceiling", facing down (X × Z = −Y); a double-sided one
    // standing on the left, its front facing away from the scene.
    push_quad(&mut mesh, Vec3::new(0.0, 2.4, -1.2), Vec3::X * 0.6, Vec3::Z * 0.5, EMIT_ONE, false);
    push_quad(&mut mesh, Vec3::new(-2.3, 0.9, -1.6), Vec3::Z * 0.45, Vec3::Y * 0.5, EMIT_TWO, false);

    let emitters_on = matches!(lighting, Lighting::Area | Lighting::All);
    let mut scene = Scene {
        path: PathBuf::from(format!("stress-{lighting:?}")),
        mesh,
        materials: materials(emitters_on),
        textures: textures(),
        ..Scene::default()
    };
    let point =
        PunctualLight::Point { position: Vec3::new(0.6, 2.0, 0.6), intensity: Vec3::new(6.0, 6.0, 5.5) };
    let spot = PunctualLight::Spot {
        position: Vec3::new(-1.0, 2.6, 1.0),
        direction: Vec3::new(0.8, -2.6, -2.4).normalize(),
        intensity: Vec3::new(14.0, 12.0, 10.0),
        inner_cone: 0.3,
        outer_cone: 0.6,
        falloff: Default::default(),
    };
    let sun = PunctualLight::Directional {
        direction: Vec3::new(0.3, -1.0, -0.45).normalize(),
        irradiance: Vec3::new(2.5, 2.4, 2.2),
    };
    match lighting {
        Lighting::Area => {}
        Lighting::Point => scene.lights = vec![point],
        Lighting::Spot => scene.lights = vec![spot],
        Lighting::Directional => scene.lights = vec![sun],
        Lighting::Sky => scene.environment = Environment { color: Vec3::new(0.4, 0.5, 0.7) },
        Lighting::EnvMap => scene.environment_map = Some(sky_map()),
        Lighting::All => {
            scene.lights = vec![point, spot, sun];
            scene.environment_map = Some(sky_map());
        }
    }
    scene.validate().expect("valid stress scene");
    scene
}

/// A 32 × 16 equirectangular sky: blue gradient above, brown ground below, a 1-texel sun.
pub fn sky_map() -> EnvironmentMap {
    let (w, h) = (32u32, 16u32);
    let texels = (0..w * h)
        .map(|i| {
            let (x, y) = (i % w, i / w);
            let c = if (x, y) == (20, 4) {
                Vec3::new(60.0, 55.0, 45.0)
            } else if y < h / 2 {
                Vec3::new(0.3, 0.45, 0.8) * (0.5 + y as f32 / h as f32)
            } else {
                Vec3::new(0.25, 0.18, 0.12)
            };
            c.extend(1.0)
        })
        .collect();
    EnvironmentMap { texture: Texture::new("sky", w, h, texels), rotation: 0.3, strength: 1.0 }
}

/// The stress camera of each model, at unit scale: all look at the scene from the front.
pub fn camera(model: Model) -> CameraDesc {
    let (from, at) = (Vec3::new(0.0, 1.4, 3.2), Vec3::new(0.0, 0.6, -1.0));
    let fov_y = 50f32.to_radians();
    let projection = match model {
        Model::Perspective => Projection::Perspective { fov_y },
        Model::Orthographic => Projection::Orthographic { half_height: 1.7 },
        Model::ThinLens => Projection::ThinLens { fov_y, lens_radius: 0.08, focus_distance: 4.0 },
        Model::Fisheye => Projection::Fisheye { fov: std::f32::consts::PI },
        Model::Equirectangular => Projection::Equirectangular,
    };
    look_at(from, at, Vec3::Y, projection)
}

/// `scene` and `camera` mapped by p ↦ scale·p + offset (on every axis), computed in f64 so the
/// only rounding is the final one to f32. What has the unit of a length scales with it: point
/// and spot light intensities by scale² (irradiance I/d² must not change), the orthographic
/// window and the thin lens's aperture and focus distance by scale. Directions, radiance,
/// directional irradiance and the environment are scale-free.
pub fn transformed(scene: &Scene, camera: &CameraDesc, scale: f64, offset: f64) -> (Scene, CameraDesc) {
    let f = |p: Vec3| (p.as_dvec3() * scale + DVec3::splat(offset)).as_vec3();
    let s = scale as f32;
    // Beyond scale 1e15 the intensity saturates at 1e30 (f32 would overflow): there the
    // tests assert only that nothing turns NaN.
    let s2 = (scale * scale).min(1e30) as f32;
    let mut scene = scene.clone();
    for p in &mut scene.mesh.positions {
        *p = f(*p);
    }
    for light in &mut scene.lights {
        match light {
            PunctualLight::Point { position, intensity }
            | PunctualLight::Spot { position, intensity, .. } => {
                *position = f(*position);
                *intensity *= s2;
            }
            PunctualLight::Directional { .. } => {}
        }
    }
    let mut camera = camera.clone();
    let m = camera.world_from_camera;
    camera.world_from_camera = Affine3A::from_mat3_translation(m.matrix3.into(), f(m.translation.into()));
    camera.projection = match camera.projection {
        Projection::Orthographic { half_height } => Projection::Orthographic { half_height: half_height * s },
        Projection::ThinLens { fov_y, lens_radius, focus_distance } => {
            Projection::ThinLens { fov_y, lens_radius: lens_radius * s, focus_distance: focus_distance * s }
        }
        p => p,
    };
    (scene, camera)
}
