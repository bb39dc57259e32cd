//! Normal maps and tangents, alpha cut-outs and glass, against the cosine law, shadow shapes, Snell and Fresnel.

use super::assets::*;
use super::harness::*;
use glam::{DVec3, Quat, UVec2, Vec2, Vec3, Vec4};
use std::f32::consts::{FRAC_PI_2, FRAC_PI_4, PI};
use tracer::scene::GltfReading;

/// A constant normal map tilting the normal ~30° along the tangent, on two ρ = 0.5 floor
/// halves lit by a 1 W/m² directional light: the left half's tangent frame comes from its
/// texture coordinates (u along +X, v along +Z: tangent +X, bitangent −∂p/∂v = −Z), the right
/// half's from a TANGENT attribute (1, 0, 0, +1) on a node turned 90° about +Y (world tangent
/// −Z, bitangent n × t = −X). Each renders ρ/π · E · (n′ · l) · G₁ with n′ the map's normal in
/// that frame and G₁ Blender's bump shadowing.
#[test]
fn normal_map_tilts_the_cosine_law() {
    let dir = TempDir::new("normal");
    let code = [191u8, 128, 237];
    png(&dir, "tilt.png", 1, 1, &[[code[0], code[1], code[2], 255]]);
    let mut g = Gltf::new("scene_features");
    let texture = g.texture("tilt.png", None);
    let material = g.material(&format!(
        r#"{{"name": "bumpy", "pbrMetallicRoughness": {{"baseColorFactor": [0.5, 0.5, 0.5, 1], "metallicFactor": 0}},
            "normalTexture": {{"index": {texture}}}, "extensions": {{"KHR_materials_specular": {{"specularFactor": 0}}}}}}"#
    ));
    let left = quad(Vec3::new(-1.0, 0.0, 0.0), Vec3::X, Vec3::Z, Vec3::Y);
    g.mesh_node(&[(&left, material)], "");
    let mut right = quad(Vec3::ZERO, Vec3::X, Vec3::Z, Vec3::Y);
    right.tangents = vec![Vec4::new(1.0, 0.0, 0.0, 1.0); 4];
    let turn = Quat::from_rotation_y(FRAC_PI_2);
    g.mesh_node(
        &[(&right, material)],
        &format!(r#", "translation": [1, 0, 0], "rotation": {}"#, arr(&turn.to_array())),
    );
    let l = Vec3::new(1.0, 2.0, 0.5).normalize();
    g.light(r#"{"type": "directional", "intensity": 683}"#, Vec3::new(0.0, 5.0, 0.0), -l);
    let scene = load(&g.write(&dir, "normal"));

    let m = Vec3::from(code.map(|c| 2.0 * c as f32 / 255.0 - 1.0));
    let n_left = (m.x * Vec3::X + m.y * Vec3::NEG_Z + m.z * Vec3::Y).normalize();
    let n_right = (m.x * Vec3::NEG_Z + m.y * Vec3::NEG_X + m.z * Vec3::Y).normalize();
    // Blender's bump shadowing of the diffuse lobe (docs/design/tracer.md §3.10; Chiang et al. 2019, as
    // Cycles' `bump_shadowing_term`): a GGX G1 for the light's angle to the unmapped normal Y,
    // with α² = ⅛·tan² of the map's tilt.
    let shadowing = |n: Vec3| {
        let tan2 = |c: f32| 1.0 / (c * c) - 1.0;
        let alpha2 = (0.125 * tan2(n.y)).clamp(0.0, 1.0);
        2.0 / (1.0 + (1.0 + alpha2 * tan2(l.y)).sqrt())
    };
    let lit = |n: Vec3| 0.5 / PI * n.dot(l) * shadowing(n);
    let (want_left, want_right) = (lit(n_left), lit(n_right));
    // Tilted ~30° each way: far from each other and from the flat floor's 0.5/π · 0.873.
    assert!((want_left - want_right).abs() > 0.03 && (want_left - 0.5 / PI * l.y).abs() > 0.01);

    let cam = Ortho::new(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::NEG_Z, 1.0, UVec2::new(32, 16));
    let r = render(&scene, &cam.desc, cam.size, 4, 1);
    assert_exact_columns(&r, |i| {
        let want = if i < 16 { want_left } else { want_right };
        (want, 1e-4 * want)
    });
}

/// A leaf: a quad at height 1 over x ∈ [1, 2] whose texture's left half has alpha 0 (cut away
/// by MASK) and right half alpha 1, lit by a sun travelling along (−1, −1, 0)/√2. The floor
/// in view (x ∈ [−1, 1]) is shadowed where the light passes the leaf's opaque half (floor
/// x ∈ [0.5, 1]) and lit as if there were no leaf elsewhere (x < 0 misses the leaf; x ∈ [0, 0.5]
/// passes its cut-out half).
#[test]
fn alpha_masked_leaf_casts_a_cut_out_shadow() {
    let dir = TempDir::new("leaf");
    png(&dir, "leaf.png", 2, 1, &[[40, 200, 40, 0], [40, 200, 40, 255]]);
    let mut g = Gltf::new("scene_features");
    let texture = g.texture("leaf.png", Some(r#"{"magFilter": 9728, "wrapS": 33071, "wrapT": 33071}"#));
    let leaf = g.material(&format!(
        r#"{{"name": "leaf", "alphaMode": "MASK", "doubleSided": true,
            "pbrMetallicRoughness": {{"baseColorTexture": {{"index": {texture}}}, "metallicFactor": 0}}}}"#
    ));
    let floor = g.material(&lambert("floor", Vec3::splat(0.5)));
    g.mesh_node(&[(&quad(Vec3::ZERO, Vec3::X * 3.0, Vec3::Z * 3.0, Vec3::Y), floor)], "");
    g.mesh_node(&[(&quad(Vec3::new(1.5, 1.0, 0.0), Vec3::X * 0.5, Vec3::Z * 2.0, Vec3::NEG_Y), leaf)], "");
    g.light(
        r#"{"type": "directional", "intensity": 683}"#,
        Vec3::new(3.0, 3.0, 0.0),
        Vec3::new(-1.0, -1.0, 0.0),
    );
    let scene = load(&g.write(&dir, "leaf"));
    let cam = Ortho::new(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::NEG_Z, 1.0, UVec2::splat(32));
    let r = render(&scene, &cam.desc, cam.size, 4, 1);
    let lit = 0.5 / PI * std::f32::consts::FRAC_1_SQRT_2;
    // Film column i covers world x ∈ [i/16 − 1, (i + 1)/16 − 1).
    assert_exact_columns(&r, |i| (if i >= 24 { 0.0 } else { lit }, 1e-4 * lit));
}

/// Adds the glass tests' backdrop to `g`: an emissive quad at z = −3, 8 wide, whose red rises
/// with x ([`ramp`]) and whose green is 1, from a 2-texel LINEAR/CLAMP texture written to `dir`.
fn ramp_backdrop(dir: &TempDir, g: &mut Gltf) {
    png(dir, "ramp.png", 2, 1, &[[0, 255, 0, 255], [255, 255, 0, 255]]);
    let texture = g.texture("ramp.png", Some(r#"{"magFilter": 9729, "wrapS": 33071, "wrapT": 33071}"#));
    let backdrop = g.material(&format!(
        r#"{{"name": "backdrop", "pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1]}}, "emissiveFactor": [1, 1, 1],
            "emissiveTexture": {{"index": {texture}}}}}"#
    ));
    g.mesh_node(
        &[(&quad(Vec3::new(0.0, 0.0, -3.0), Vec3::X * 4.0, Vec3::NEG_Y * 4.0, Vec3::Z), backdrop)],
        "",
    );
}

/// The red [`ramp_backdrop`] emits at x. The texels are sRGB: filtered encoded, then decoded
/// (docs/design/tracer.md §3.10), so the red is the decoded linear ramp of the encoded value.
fn ramp(x: f64) -> f64 {
    let decode = |c: f64| if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
    decode(((x + 2.0) / 4.0).clamp(0.0, 1.0))
}

/// Refraction through a glass ball (transmission 1, ior 1.5, radius 1, a solid by its
/// `KHR_materials_volume` thickness in either reading) seen by an orthographic
/// camera against an emissive backdrop at z = −3 whose red rises with x (R = the sRGB decoding
/// of clamp((x + 2)/4), G = 1, from a 2-texel LINEAR/CLAMP texture). For each pixel the
/// closed form refracts the parallel ray into and out of the sphere by Snell's law (vectors
/// below), lands it on the backdrop, and weights it by the exact Fresnel transmittances: the
/// expected G is (1 − F₁)(1 − F₂) and R/G the backdrop ramp where the ray lands (plus the small
/// share of paths reflected inside the ball: once, they turn back by ~160° and see the black sky;
/// twice, ~0.2 %, they reach the backdrop elsewhere).
#[test]
fn glass_ball_refracts_as_snell_and_fresnel_say() {
    let dir = TempDir::new("glass");
    let mut g = Gltf::new("scene_features");
    ramp_backdrop(&dir, &mut g);
    let glass = g.material(
        r#"{"name": "glass", "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}, "KHR_materials_ior": {"ior": 1.5},
                           "KHR_materials_volume": {"thicknessFactor": 2}}}"#,
    );
    g.mesh_node(&[(&sphere(Vec3::ZERO, 1.0, 96, 192), glass)], "");
    let scene = load(&g.write(&dir, "glass"));
    // Refraction of unit d through a surface with unit normal n facing against d, eta = n_i/n_t:
    // the transmitted direction and the unpolarised Fresnel reflectance.
    let refract = |d: DVec3, n: DVec3, eta: f64| {
        let cos_i = -n.dot(d);
        let cos_t = (1.0 - eta * eta * (1.0 - cos_i * cos_i)).sqrt();
        let t = eta * d + (eta * cos_i - cos_t) * n;
        let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
        let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
        (t, 0.5 * (rs * rs + rp * rp))
    };
    // (R, G) for the ray along −z through (x, y): G = (1 − F₁)(1 − F₂), R = G × the ramp where
    // it lands, plus the paths reflected inside the ball k = 1 … 3 times before they leave
    // (weight (1 − F₁)·F^k·(1 − F); those that leave forwards and meet the backdrop count).
    let expected_at = |x: f64, y: f64| -> Vec3 {
        let rho2 = x * x + y * y;
        if rho2 >= 1.0 {
            return Vec3::new(ramp(x) as f32, 1.0, 0.0);
        }
        let mut p = DVec3::new(x, y, (1.0 - rho2).sqrt());
        let (mut d, f1) = refract(DVec3::NEG_Z, p, 1.0 / 1.5);
        let (mut w, mut rg) = (1.0 - f1, (0.0, 0.0));
        for _ in 0..4 {
            let q = p - 2.0 * p.dot(d) * d; // the next point on the sphere, from inside
            let (out, f) = refract(d, -q, 1.5);
            let land = q + out * ((-3.0 - q.z) / out.z);
            if out.z < 0.0 && land.x.abs() <= 4.0 && land.y.abs() <= 4.0 {
                rg.0 += w * (1.0 - f) * ramp(land.x);
                rg.1 += w * (1.0 - f);
            }
            d -= 2.0 * d.dot(q) * q; // reflected inside
            w *= f;
            p = q;
        }
        Vec3::new(rg.0 as f32, rg.1 as f32, 0.0)
    };

    // Chosen rays: a tiny orthographic window (1e-5 across) at offset (x, y) is one ray.
    for (x, y) in [(0.1f32, 0.0f32), (0.3, 0.0), (0.5, 0.0), (0.7, 0.0), (-0.40625, 0.28125), (0.2, -0.45)] {
        let probe = Ortho::new(Vec3::new(x, y, 5.0), Vec3::new(x, y, 0.0), Vec3::Y, 1e-5, UVec2::ONE);
        let r = render(&scene, &probe.desc, probe.size, 1024, 4);
        let (got, want) = (r.images.image.get(0, 0), expected_at(x as f64, y as f64));
        println!(
            "glass ray at ({x}, {y}): R/G {} (Snell {}), G {} (Fresnel {})",
            got.x / got.y,
            want.x / want.y,
            got.y,
            want.y
        );
        // Where it lands: R/G is the ramp there, whatever the Fresnel coin flips. (The rare paths
        // reflected twice inside, ~1.6 of the 1024 samples, add ±1e-3 of noise.)
        assert!(
            (got.x / got.y - want.x / want.y).abs() < 3e-3,
            "the ray at ({x}, {y}) lands at ramp {} but Snell's law says {}",
            got.x / got.y,
            want.x / want.y
        );
        // How much gets through: within the binomial noise of the Fresnel choices.
        let sigma = (r.images.variance.get(0, 0).y / 1024.0).sqrt();
        assert!(
            (got.y - want.y).abs() < 5.0 * sigma + 1e-3,
            "transmittance at ({x}, {y}): {} vs {}",
            got.y,
            want.y
        );
    }

    // The whole ball: every pixel's landing, in aggregate (a pixel of 64 samples holding one of
    // the rare twice-reflected paths moves by up to ~0.01: that is noise, not bias), and the
    // backdrop around it exactly.
    let cam = Ortho::new(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, Vec3::Y, 1.25, UVec2::splat(40));
    let r = render(&scene, &cam.desc, cam.size, 64, 4);
    let expected = |f: Vec2| {
        let o = cam.origin(f);
        expected_at(o.x as f64, o.y as f64)
    };
    let radius_of = |i: u32, j: u32| {
        let corners = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)];
        let r: Vec<f32> = corners
            .iter()
            .map(|(a, b)| cam.origin(Vec2::new(i as f32 + a, j as f32 + b)).truncate().length())
            .collect();
        (r.iter().copied().fold(f32::MAX, f32::min), r.iter().copied().fold(0.0, f32::max))
    };
    let (mut diffs, mut beside) = (Vec::new(), 0);
    for j in 0..40 {
        for i in 0..40 {
            let (lo, hi) = radius_of(i, j);
            if hi < 0.8 {
                let want = footprint(i, j, 8, expected);
                let got = r.images.image.get(i, j);
                diffs.push((got.x / got.y - want.x / want.y).abs());
            } else if lo > 1.0 {
                beside += 1;
                let want = footprint(i, j, 8, expected);
                check("glass (backdrop seen directly)", &r, i, j, want, 1e-4, 1e-5);
            }
        }
    }
    let n = diffs.len() as f32;
    let mean = diffs.iter().sum::<f32>() / n;
    let within = diffs.iter().filter(|d| **d < 5e-3).count() as f32 / n;
    let max = diffs.iter().copied().fold(0.0, f32::max);
    println!(
        "glass image: {n} pixels through the ball, mean |ΔR/G| {mean:.2e}, {:.1} % within 5e-3, max {max:.3}",
        100.0 * within
    );
    assert!(n > 300.0 && beside > 300, "{n} pixels through the ball, {beside} beside it");
    assert!(mean < 2e-3 && within > 0.95 && max < 0.03, "landings disagree with Snell's law");
}

/// `KHR_materials_transmission` without `KHR_materials_volume` in its two readings: a smooth
/// glass sheet (one quad, ior 1.5) turned 45° about y, in front of the ramp backdrop of
/// `glass_ball_refracts_as_snell_and_fresnel_say`, each probe one orthographic ray along −z.
/// The specification's thin wall lets the ray through unbent, so R/G is the ramp right behind
/// it, and G the wall's transmittance 1 − F(45°); Blender's reading (a file it wrote, or
/// `--gltf-reading blender`) makes the sheet the face of a refracting solid, so the ray bends by
/// Snell's law and lands ~0.9 to the side. (Before the thin wall, both readings bent it.)
#[test]
fn thin_sheet_transmits_unbent_by_the_specification() {
    let dir = TempDir::new("thin-sheet");
    let mut g = Gltf::new("scene_features");
    ramp_backdrop(&dir, &mut g);
    let glass = g.material(
        r#"{"name": "sheet", "doubleSided": true,
            "pbrMetallicRoughness": {"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0},
            "extensions": {"KHR_materials_transmission": {"transmissionFactor": 1}, "KHR_materials_ior": {"ior": 1.5}}}"#,
    );
    let n = Vec3::new(1.0, 0.0, 1.0).normalize();
    g.mesh_node(&[(&quad(Vec3::ZERO, Vec3::new(1.5, 0.0, -1.5), Vec3::Y * 2.0, n), glass)], "");
    let spec = load(&g.write(&dir, "sheet"));
    assert_eq!(spec.reading, GltfReading::Spec, "not written by Blender");
    let mut blender = spec.clone();
    blender.set_reading(GltfReading::Blender);

    // The ray along −z meets the sheet (normal n, facing it) at 45°: Snell's direction inside
    // and the unpolarised Fresnel reflectance there.
    let (cos_i, eta) = (FRAC_PI_4.cos() as f64, 1.0 / 1.5);
    let cos_t = (1.0 - eta * eta * (1.0 - cos_i * cos_i)).sqrt();
    let bent = eta * DVec3::NEG_Z + (eta * cos_i - cos_t) * n.as_dvec3();
    let rs = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let rp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    let fresnel = 0.5 * (rs * rs + rp * rp);
    for x in [-0.6f32, -0.2, 0.2, 0.6] {
        let probe = Ortho::new(Vec3::new(x, 0.3, 5.0), Vec3::new(x, 0.3, 0.0), Vec3::Y, 1e-5, UVec2::ONE);
        let thin = render(&spec, &probe.desc, probe.size, 1024, 4);
        let solid = render(&blender, &probe.desc, probe.size, 1024, 4);
        let (thin_px, solid_px) = (thin.images.image.get(0, 0), solid.images.image.get(0, 0));
        // The sheet's point is (x, y, −x); the bent ray lands on the backdrop at z = −3.
        let landed = x as f64 + bent.x * ((-3.0 + x as f64) / bent.z);
        println!(
            "sheet ray at x {x}: spec R/G {} (straight {}), G {} (1 − F {}); Blender R/G {} (Snell {})",
            thin_px.x / thin_px.y,
            ramp(x as f64),
            thin_px.y,
            1.0 - fresnel,
            solid_px.x / solid_px.y,
            ramp(landed)
        );
        assert!(
            (thin_px.x / thin_px.y - ramp(x as f64) as f32).abs() < 1e-3,
            "the specification's thin wall displaced the ray at x {x}: R/G {} behind it {}",
            thin_px.x / thin_px.y,
            ramp(x as f64)
        );
        let sigma = (thin.images.variance.get(0, 0).y / 1024.0).sqrt();
        assert!(
            (thin_px.y as f64 - (1.0 - fresnel)).abs() < 5.0 * sigma as f64 + 1e-3,
            "thin wall transmittance at x {x}: {} vs {}",
            thin_px.y,
            1.0 - fresnel
        );
        assert!(
            (solid_px.x / solid_px.y - ramp(landed) as f32).abs() < 1e-3 && (landed - x as f64).abs() > 0.5,
            "Blender's reading did not refract the ray at x {x}: R/G {} where Snell lands it at {landed} ({})",
            solid_px.x / solid_px.y,
            ramp(landed)
        );
    }
}

/// A half-metal glass (metallic 0.5, transmission 1, white, smooth) under a sun overhead, seen
/// at 45°: Cycles' Principled BSDF splits it into metal (½) and glass (½) with no diffuse part,
/// so neither the smooth metal nor the glass sends the sun towards the camera and the picture
/// is black. Taking the whole opaque material (half of it diffuse) whenever the glass was not
/// chosen turned such glass milky: ¼ of a white Lambertian. The control without transmission
/// shows that this view does see a diffuse part where there is one.
#[test]
fn half_metal_glass_has_no_diffuse_part() {
    let dir = TempDir::new("half-metal-glass");
    let mean = |transmission: f32| {
        let mut g = Gltf::new("scene_features");
        let plane = g.material(&format!(
            r#"{{"name": "probe", "doubleSided": true,
                "pbrMetallicRoughness": {{"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0.5, "roughnessFactor": 0}},
                "extensions": {{"KHR_materials_transmission": {{"transmissionFactor": {transmission}}}}}}}"#
        ));
        g.mesh_node(&[(&quad(Vec3::ZERO, Vec3::X * 10.0, Vec3::Z * 10.0, Vec3::Y), plane)], "");
        g.light(r#"{"type": "directional", "intensity": 683}"#, Vec3::Y, Vec3::NEG_Y);
        let scene = load(&g.write(&dir, &format!("probe{transmission}")));
        let cam = Ortho::new(Vec3::new(0.0, 3.0, 3.0), Vec3::ZERO, Vec3::Y, 1.0, UVec2::splat(16));
        let r = render(&scene, &cam.desc, cam.size, 64, 2);
        let image = &r.images.image;
        let sum: Vec3 =
            (0..16).flat_map(|j| (0..16).map(move |i| (i, j))).map(|(i, j)| image.get(i, j)).sum();
        sum / 256.0
    };
    let opaque = mean(0.0);
    assert!(opaque.min_element() > 0.05, "the control sees no diffuse part: {opaque}");
    let glass = mean(1.0);
    assert!(
        glass.max_element() < 1e-3,
        "half-metal glass is milky: {glass} (the opaque half-metal: {opaque})"
    );
}

/// `KHR_materials_unlit` as Blender imports it: the camera sees the base colour itself (an
/// emission of strength 1 for camera rays), and every other ray passes through, so the unlit
/// quad floating over a floor casts no shadow under a slanting sun and lights nothing. With one
/// scattering vertex and a sun every sample is exact: the quad's pixels are its colour, every
/// floor pixel ρ/π · E · cos 45°, the quad's shadow included.
#[test]
fn unlit_surfaces_show_their_colour_to_the_camera_alone() {
    let dir = TempDir::new("unlit");
    let mut g = Gltf::new("scene_features");
    let floor = g.material(&lambert("floor", Vec3::splat(0.5)));
    let unlit = g.material(
        r#"{"name": "unlit", "pbrMetallicRoughness": {"baseColorFactor": [0.8, 0.2, 0.1, 1]},
            "emissiveFactor": [1, 1, 1], "extensions": {"KHR_materials_unlit": {}}}"#,
    );
    g.mesh_node(&[(&quad(Vec3::ZERO, Vec3::X * 10.0, Vec3::Z * 10.0, Vec3::Y), floor)], "");
    g.mesh_node(&[(&quad(Vec3::Y, Vec3::X * 0.5, Vec3::Z * 0.5, Vec3::Y), unlit)], "");
    g.light(r#"{"type": "directional", "intensity": 683}"#, Vec3::Y, Vec3::new(1.0, -1.0, 0.0));
    let path = g.write(&dir, "unlit");
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace(r#""KHR_materials_ior"]"#, r#""KHR_materials_ior", "KHR_materials_unlit"]"#);
    std::fs::write(&path, text).unwrap();
    let scene = load(&path);
    let cam = Ortho::new(Vec3::new(0.0, 5.0, 0.0), Vec3::ZERO, Vec3::NEG_Z, 2.0, UVec2::splat(32));
    let r = render(&scene, &cam.desc, cam.size, 4, 1);
    let floor_value = 0.5 / PI * FRAC_PI_4.cos();
    let (mut quad_pixels, mut shadow_pixels) = (0, 0);
    for j in 0..32 {
        for i in 0..32 {
            let p = cam.on_plane_y(Vec2::new(i as f32 + 0.5, j as f32 + 0.5), 0.0);
            let got = r.images.image.get(i, j);
            let want = if p.x.abs() < 0.5 && p.z.abs() < 0.5 {
                quad_pixels += 1;
                Vec3::new(0.8, 0.2, 0.1)
            } else {
                shadow_pixels += usize::from(p.x > 0.5 && p.x < 1.5 && p.z.abs() < 0.5);
                Vec3::splat(floor_value)
            };
            assert!((got - want).abs().max_element() < 1e-5, "({i}, {j}) at {p}: {got} vs {want}");
        }
    }
    assert_eq!((quad_pixels, shadow_pixels), (64, 64));
}
