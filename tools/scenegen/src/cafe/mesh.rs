//! Triangle meshes with per-vertex normals and texture coordinates, and the smooth primitives the
//! café is built from: parametric surfaces (ellipsoids, tubes, tori, lofts), surfaces of
//! revolution from a profile, boxes and quads.
//!
//! Curved surfaces are evaluated in f64 and their normals come from the surface's own partial
//! derivatives (central differences), so they are smooth and exact to ~1e-9, seams included.
//! Every triangle is wound counter-clockwise around its vertices' normals.

use glam::{Affine3A, DVec2, DVec3, Mat3A, Vec2, Vec3, Vec4};
use std::f64::consts::TAU;

#[derive(Clone, Default, Debug)]
pub struct Mesh {
    pub positions: Vec<Vec3>,
    pub normals: Vec<Vec3>,
    pub uvs: Vec<Vec2>,
    /// Empty, or one glTF tangent (xyz, handedness w) per vertex.
    pub tangents: Vec<Vec4>,
    pub indices: Vec<u32>,
}

impl Mesh {
    pub fn triangle_count(&self) -> usize {
        self.indices.len() / 3
    }

    /// Appends `other`'s vertices and triangles.
    pub fn append(&mut self, other: Mesh) {
        assert!(
            self.positions.is_empty() || self.tangents.is_empty() == other.tangents.is_empty(),
            "appending meshes with and without tangents"
        );
        let base = self.positions.len() as u32;
        self.positions.extend(other.positions);
        self.normals.extend(other.normals);
        self.uvs.extend(other.uvs);
        self.tangents.extend(other.tangents);
        self.indices.extend(other.indices.into_iter().map(|i| i + base));
    }

    /// The mesh moved by `m` (normals by the inverse transpose, tangents by `m`).
    pub fn transformed(mut self, m: Affine3A) -> Mesh {
        let normal_matrix: Mat3A = m.matrix3.inverse().transpose();
        for p in &mut self.positions {
            *p = m.transform_point3(*p);
        }
        for n in &mut self.normals {
            *n = normal_matrix.mul_vec3(*n).normalize();
        }
        for t in &mut self.tangents {
            let xyz = m.transform_vector3(t.truncate()).normalize();
            *t = xyz.extend(t.w);
        }
        if m.matrix3.determinant() < 0.0 {
            for tri in self.indices.chunks_exact_mut(3) {
                tri.swap(1, 2);
            }
        }
        self
    }

    /// Texture coordinates replaced by a planar projection: (p·a, p·b).
    pub fn planar_uv(mut self, a: Vec3, b: Vec3) -> Mesh {
        for (uv, p) in self.uvs.iter_mut().zip(&self.positions) {
            *uv = Vec2::new(p.dot(a), p.dot(b));
        }
        self
    }

    /// The same surface facing the other way (normals and winding reversed).
    pub fn flipped(mut self) -> Mesh {
        for n in &mut self.normals {
            *n = -*n;
        }
        for tri in self.indices.chunks_exact_mut(3) {
            tri.swap(1, 2);
        }
        self
    }

    /// Gives every vertex the same tangent (flat, axis-aligned texture mapping).
    pub fn with_tangent(mut self, t: Vec4) -> Mesh {
        self.tangents = vec![t; self.positions.len()];
        self
    }

    /// Adds triangle (a, b, c) wound counter-clockwise around its vertices' normals; triangles of
    /// (nearly) zero area, such as those at a sphere's poles, are left out.
    fn push_triangle(&mut self, a: u32, b: u32, c: u32) {
        let [pa, pb, pc] = [a, b, c].map(|i| self.positions[i as usize]);
        let face = (pb - pa).cross(pc - pa);
        let scale = (pb - pa).length_squared().max((pc - pa).length_squared());
        if face.length_squared() <= 1e-12 * scale * scale || scale == 0.0 {
            return;
        }
        let n = self.normals[a as usize] + self.normals[b as usize] + self.normals[c as usize];
        if face.dot(n) >= 0.0 { self.indices.extend([a, b, c]) } else { self.indices.extend([a, c, b]) }
    }

    fn push_vertex(&mut self, p: DVec3, n: DVec3, uv: DVec2) -> u32 {
        self.positions.push(p.as_vec3());
        self.normals.push(n.normalize().as_vec3());
        self.uvs.push(uv.as_vec2());
        (self.positions.len() - 1) as u32
    }

    /// A parametric surface over [0, 1]²: `f(u, v)`, sampled on an (nu + 1) × (nv + 1) grid, with
    /// texture coordinates (u · uv_scale.x, v · uv_scale.y). The normal is ∂f/∂u × ∂f/∂v (negated
    /// with `flip`); where that vanishes (a pole) it is taken a little inside the domain.
    pub fn parametric(nu: u32, nv: u32, uv_scale: DVec2, flip: bool, f: impl Fn(f64, f64) -> DVec3) -> Mesh {
        let mut mesh = Mesh::default();
        let h = 1e-6;
        let normal_at = |u: f64, v: f64| {
            let du = (f(u + h, v) - f(u - h, v)) / (2.0 * h);
            let dv = (f(u, v + h) - f(u, v - h)) / (2.0 * h);
            du.cross(dv)
        };
        for j in 0..=nv {
            let v = f64::from(j) / f64::from(nv);
            for i in 0..=nu {
                let u = f64::from(i) / f64::from(nu);
                let mut n = normal_at(u, v);
                if n.length() < 1e-9 {
                    let inside = if v < 0.5 { v + 1e-4 } else { v - 1e-4 };
                    n = normal_at(u, inside);
                }
                let n = if flip { -n } else { n };
                mesh.push_vertex(f(u, v), n, DVec2::new(u, v) * uv_scale);
            }
        }
        mesh.grid_triangles(nu, nv);
        mesh
    }

    fn grid_triangles(&mut self, nu: u32, nv: u32) {
        let row = nu + 1;
        for j in 0..nv {
            for i in 0..nu {
                let a = j * row + i;
                let (b, c, d) = (a + 1, a + row + 1, a + row);
                self.push_triangle(a, b, c);
                self.push_triangle(a, c, d);
            }
        }
    }
}

/// An orthonormal pair perpendicular to unit `d`, with e1 × e2 = d (deterministic).
fn perpendicular_frame(d: DVec3) -> (DVec3, DVec3) {
    let helper = if d.y.abs() < 0.9 { DVec3::Y } else { DVec3::X };
    let e1 = helper.cross(d).normalize();
    (e1, d.cross(e1))
}

/// An ellipsoid with semi-axes `radii` (before `rotation`), `nu` segments around, `nv` from pole
/// to pole; texture u runs around the y axis.
pub fn ellipsoid(center: Vec3, radii: Vec3, rotation: Mat3A, nu: u32, nv: u32, uv_scale: DVec2) -> Mesh {
    let (c, r) = (center.as_dvec3(), radii.as_dvec3());
    let rot = glam::DMat3::from_cols(
        Vec3::from(rotation.x_axis).as_dvec3(),
        Vec3::from(rotation.y_axis).as_dvec3(),
        Vec3::from(rotation.z_axis).as_dvec3(),
    );
    Mesh::parametric(nu, nv, uv_scale, true, move |u, v| {
        let (theta, phi) = (TAU * u, std::f64::consts::PI * v);
        c + rot * (r * DVec3::new(phi.sin() * theta.cos(), phi.cos(), -phi.sin() * theta.sin()))
    })
}

/// A sphere.
pub fn sphere(center: Vec3, radius: f32, nu: u32, nv: u32) -> Mesh {
    ellipsoid(center, Vec3::splat(radius), Mat3A::IDENTITY, nu, nv, DVec2::ONE)
}

/// A shell over the axis-aligned ellipsoid (`center`, semi-axes `radii`), e.g. hair over a
/// skull: the part of the ellipsoid scaled by `scale` (> 1) seen from the centre within
/// `phi_max` radians of the direction `rotation` × +y, closed along its edge by a band down to
/// the ellipsoid itself, so that it hugs the ellipsoid whatever its tilt and shows no inside.
pub fn ellipsoid_shell(
    center: Vec3,
    radii: Vec3,
    scale: f64,
    rotation: Mat3A,
    phi_max: f64,
    nu: u32,
    nv: u32,
) -> Mesh {
    let (c, r) = (center.as_dvec3(), radii.as_dvec3());
    let rot = glam::DMat3::from_cols(
        Vec3::from(rotation.x_axis).as_dvec3(),
        Vec3::from(rotation.y_axis).as_dvec3(),
        Vec3::from(rotation.z_axis).as_dvec3(),
    );
    let dir = move |theta: f64, phi: f64| {
        rot * DVec3::new(phi.sin() * theta.cos(), phi.cos(), -phi.sin() * theta.sin())
    };
    let mut m =
        Mesh::parametric(nu, nv, DVec2::ONE, true, move |u, v| c + r * dir(TAU * u, phi_max * v) * scale);
    m.append(Mesh::parametric(nu, 2, DVec2::ONE, false, move |u, v| {
        c + r * dir(TAU * u, phi_max) * (1.0 + (scale - 1.0) * v)
    }));
    m
}

/// A tapered open tube from `a` (radius `ra`) to `b` (radius `rb`); texture u runs around
/// (scaled to metres of the mean circumference × `uv_per_metre`), v along.
pub fn tube(a: Vec3, b: Vec3, ra: f32, rb: f32, nu: u32, nv: u32, uv_per_metre: f64) -> Mesh {
    let (a, b) = (a.as_dvec3(), b.as_dvec3());
    let (ra, rb) = (f64::from(ra), f64::from(rb));
    let len = (b - a).length();
    let d = (b - a) / len;
    let (e1, e2) = perpendicular_frame(d);
    let uv = DVec2::new(TAU * 0.5 * (ra + rb), len) * uv_per_metre;
    Mesh::parametric(nu, nv, uv, false, move |u, v| {
        let t = TAU * u;
        let r = ra + (rb - ra) * v;
        a + (b - a) * v + (e1 * t.cos() + e2 * t.sin()) * r
    })
}

/// A tapered capsule from `a` (radius `ra`) to `b` (radius `rb`): a tube closed by a half
/// sphere at each end, one smooth surface; `nu` segments around, `nv` rows along the tube and
/// `nu / 4` rows on each cap.
pub fn capsule(a: Vec3, b: Vec3, ra: f32, rb: f32, nu: u32, nv: u32, uv_per_metre: f64) -> Mesh {
    let (a, b) = (a.as_dvec3(), b.as_dvec3());
    let (ra, rb) = (f64::from(ra), f64::from(rb));
    let len = (b - a).length();
    let d = (b - a) / len;
    let (e1, e2) = perpendicular_frame(d);
    let cap = nu / 4;
    let rows = nv + 2 * cap;
    let (v0, v1) = (f64::from(cap) / f64::from(rows), f64::from(cap + nv) / f64::from(rows));
    let uv = DVec2::new(TAU * 0.5 * (ra + rb), len + ra + rb) * uv_per_metre;
    Mesh::parametric(nu, rows, uv, false, move |u, v| {
        let t = TAU * u;
        let radial = e1 * t.cos() + e2 * t.sin();
        if v < v0 {
            // The cap at a: polar angle from −d.
            let phi = std::f64::consts::FRAC_PI_2 * v / v0;
            a + (radial * phi.sin() - d * phi.cos()) * ra
        } else if v > v1 {
            let phi = std::f64::consts::FRAC_PI_2 * (1.0 - v) / (1.0 - v1);
            b + (radial * phi.sin() + d * phi.cos()) * rb
        } else {
            let s = (v - v0) / (v1 - v0);
            a + (b - a) * s + radial * (ra + (rb - ra) * s)
        }
    })
}

/// A torus around `axis` through `center` (major radius `major`, tube radius `minor`), swept
/// over the angle range `[a0, a1]` (radians; a full turn for a closed ring). The angle is
/// measured from `start` (perpendicular to `axis`) towards `axis × start`.
#[allow(clippy::too_many_arguments)]
pub fn torus(
    center: Vec3,
    axis: Vec3,
    start: Vec3,
    major: f32,
    minor: f32,
    (a0, a1): (f64, f64),
    nu: u32,
    nv: u32,
    uv_per_metre: f64,
) -> Mesh {
    let (c, ax) = (center.as_dvec3(), axis.as_dvec3().normalize());
    let e1 = start.as_dvec3().reject_from(ax).normalize();
    let e2 = ax.cross(e1);
    let (big, small) = (f64::from(major), f64::from(minor));
    let uv = DVec2::new(big * (a1 - a0), TAU * small) * uv_per_metre;
    Mesh::parametric(nu, nv, uv, false, move |u, v| {
        let (theta, phi) = (a0 + (a1 - a0) * u, TAU * v);
        let radial = e1 * theta.cos() + e2 * theta.sin();
        c + radial * (big + small * phi.cos()) + ax * (small * phi.sin())
    })
}

/// One section of a loft: centre (x, z) and semi-axes (rx, rz) at height y.
#[derive(Clone, Copy, Debug)]
pub struct Section {
    pub y: f64,
    pub cx: f64,
    pub cz: f64,
    pub rx: f64,
    pub rz: f64,
}

/// A smooth closed surface through elliptical horizontal `sections` (bottom to top; make the
/// first and last radii 0 to close it), interpolated with Catmull–Rom splines.
pub fn loft(sections: &[Section], nu: u32, nv: u32, uv_per_metre: f64) -> Mesh {
    let keys: Vec<[f64; 5]> = sections.iter().map(|s| [s.y, s.cx, s.cz, s.rx, s.rz]).collect();
    let segments = (keys.len() - 1) as f64;
    let at = move |v: f64| -> [f64; 5] {
        let x = (v * segments).clamp(0.0, segments);
        let k = (x.floor() as usize).min(keys.len() - 2);
        let t = x - k as f64;
        let get = |i: isize| keys[i.clamp(0, keys.len() as isize - 1) as usize];
        let (p0, p1, p2, p3) =
            (get(k as isize - 1), get(k as isize), get(k as isize + 1), get(k as isize + 2));
        std::array::from_fn(|c| {
            let (a, b, cc, d) = (p0[c], p1[c], p2[c], p3[c]);
            0.5 * (2.0 * b
                + (cc - a) * t
                + (2.0 * a - 5.0 * b + 4.0 * cc - d) * t * t
                + (3.0 * b - a - 3.0 * cc + d) * t * t * t)
        })
    };
    let height = sections.last().unwrap().y - sections[0].y;
    let girth = sections.iter().map(|s| s.rx + s.rz).fold(0.0, f64::max) * std::f64::consts::PI;
    Mesh::parametric(nu, nv, DVec2::new(girth, height) * uv_per_metre, false, move |u, v| {
        let [y, cx, cz, rx, rz] = at(v);
        let t = TAU * u;
        DVec3::new(cx + rx.max(0.0) * t.cos(), y, cz - rz.max(0.0) * t.sin())
    })
}

/// A profile for [`lathe`]: smooth strands of (radius, height) points, traversed with the solid
/// on the left (up the outside, down the inside); a crease starts a new strand.
#[derive(Default)]
pub struct Profile {
    strands: Vec<Vec<DVec2>>,
}

impl Profile {
    pub fn start(r: f64, y: f64) -> Profile {
        Profile { strands: vec![vec![DVec2::new(r, y)]] }
    }

    fn last(&self) -> DVec2 {
        *self.strands.last().unwrap().last().unwrap()
    }

    /// A straight segment to (r, y) in `n` steps.
    pub fn line(mut self, r: f64, y: f64, n: u32) -> Profile {
        let (a, b) = (self.last(), DVec2::new(r, y));
        let strand = self.strands.last_mut().unwrap();
        strand.extend((1..=n).map(|i| a.lerp(b, f64::from(i) / f64::from(n))));
        self
    }

    /// An arc around (cr, cy) of radius `rad` from angle `a0` to `a1` (radians, 0 = +r,
    /// π/2 = +y) in `n` steps, starting from a point on it (the current point is joined by a
    /// straight step if it is elsewhere).
    pub fn arc(mut self, cr: f64, cy: f64, rad: f64, a0: f64, a1: f64, n: u32) -> Profile {
        let p = |a: f64| DVec2::new(cr + rad * a.cos(), cy + rad * a.sin());
        let strand = self.strands.last_mut().unwrap();
        let first = if strand.last().unwrap().distance(p(a0)) < 1e-9 { 1 } else { 0 };
        strand.extend((first..=n).map(|i| p(a0 + (a1 - a0) * f64::from(i) / f64::from(n))));
        self
    }

    /// Appends the given points (a smooth run).
    pub fn points(mut self, points: impl IntoIterator<Item = (f64, f64)>) -> Profile {
        let strand = self.strands.last_mut().unwrap();
        for (r, y) in points {
            let p = DVec2::new(r, y);
            if strand.last().is_none_or(|q| q.distance(p) > 1e-9) {
                strand.push(p);
            }
        }
        self
    }

    /// A hard edge: the next segments get their own normals.
    pub fn crease(mut self) -> Profile {
        let p = self.last();
        self.strands.push(vec![p]);
        self
    }
}

/// A surface of revolution about the y axis through `center`: texture u runs around
/// (`nu` segments), v along the profile (both in metres × `uv_per_metre`).
pub fn lathe(profile: &Profile, center: Vec3, nu: u32, uv_per_metre: f64) -> Mesh {
    let c = center.as_dvec3();
    let mut mesh = Mesh::default();
    let max_r = profile.strands.iter().flatten().map(|p| p.x).fold(0.0, f64::max);
    let mut arc_length = 0.0;
    for strand in &profile.strands {
        if strand.len() < 2 {
            continue;
        }
        let first = mesh.positions.len() as u32;
        for (k, p) in strand.iter().enumerate() {
            if k > 0 {
                arc_length += p.distance(strand[k - 1]);
            }
            let tangent = strand[(k + 1).min(strand.len() - 1)] - strand[k.saturating_sub(1)];
            assert!(tangent.length() > 1e-12, "a lathe profile repeats a point at {p}");
            let n2 = DVec2::new(tangent.y, -tangent.x).normalize();
            for i in 0..=nu {
                let u = f64::from(i) / f64::from(nu);
                let (s, co) = (TAU * u).sin_cos();
                let pos = c + DVec3::new(p.x * co, p.y, -p.x * s);
                let n = DVec3::new(n2.x * co, n2.y, -n2.x * s);
                mesh.push_vertex(pos, n, DVec2::new(u * TAU * max_r, arc_length) * uv_per_metre);
            }
        }
        let before = mesh.indices.len();
        let row = nu + 1;
        for j in 0..strand.len() as u32 - 1 {
            for i in 0..nu {
                let a = first + j * row + i;
                mesh.push_triangle(a, a + 1, a + row + 1);
                mesh.push_triangle(a, a + row + 1, a + row);
            }
        }
        debug_assert!(mesh.indices.len() >= before);
    }
    mesh
}

/// A flat quad with corner `origin` and edges `eu`, `ev` (normal eu × ev), texture coordinates
/// in metres × `uv_per_metre` from `uv_origin`.
pub fn quad(origin: Vec3, eu: Vec3, ev: Vec3, uv_origin: Vec2, uv_per_metre: f32) -> Mesh {
    let n = eu.cross(ev).normalize();
    let (lu, lv) = (eu.length() * uv_per_metre, ev.length() * uv_per_metre);
    let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    let mut m = Mesh::default();
    for (a, b) in corners {
        m.positions.push(origin + eu * a + ev * b);
        m.normals.push(n);
        m.uvs.push(uv_origin + Vec2::new(a * lu, b * lv));
    }
    m.push_triangle(0, 1, 2);
    m.push_triangle(0, 2, 3);
    m
}

/// An axis-aligned box from `lo` to `hi` with flat faces, texture coordinates in metres ×
/// `uv_per_metre` (u along the face's longer horizontal edge).
pub fn cuboid(lo: Vec3, hi: Vec3, uv_per_metre: f32) -> Mesh {
    let d = hi - lo;
    let (x, y, z) = (Vec3::X * d.x, Vec3::Y * d.y, Vec3::Z * d.z);
    let mut m = Mesh::default();
    let faces = [
        (lo, z, y),     // −x
        (lo + x, y, z), // +x
        (lo, x, z),     // −y
        (lo + y, z, x), // +y
        (lo, y, x),     // −z
        (lo + z, x, y), // +z
    ];
    for (o, eu, ev) in faces {
        m.append(quad(o, eu, ev, Vec2::ZERO, uv_per_metre));
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    /// For a closed surface around `inside`, normals point away from it on average and every
    /// triangle agrees with its vertex normals.
    fn check_outward(m: &Mesh, inside: Vec3) {
        assert!(!m.indices.is_empty());
        let mut outward = 0.0;
        for t in m.indices.chunks_exact(3) {
            let [a, b, c] = [t[0], t[1], t[2]].map(|i| m.positions[i as usize]);
            let face = (b - a).cross(c - a);
            let n: Vec3 = t.iter().map(|&i| m.normals[i as usize]).sum();
            assert!(face.dot(n) > 0.0);
            outward += face.dot((a + b + c) / 3.0 - inside);
        }
        assert!(outward > 0.0, "inward: {} triangles", m.triangle_count());
        for (p, n) in m.positions.iter().zip(&m.normals) {
            assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-5, "{p} {n}");
        }
    }

    #[test]
    fn primitives_face_outward() {
        let c = Vec3::new(0.3, 1.0, -0.2);
        check_outward(&sphere(c, 0.5, 16, 8), c);
        check_outward(
            &ellipsoid(c, Vec3::new(0.2, 0.5, 0.3), Mat3A::from_rotation_x(0.4), 16, 8, DVec2::ONE),
            c,
        );
        check_outward(
            &capsule(c, c + Vec3::new(0.1, 0.5, 0.2), 0.1, 0.05, 16, 4, 1.0),
            c + Vec3::new(0.05, 0.25, 0.1),
        );
        let ring = torus(c, Vec3::Y, Vec3::X, 0.5, 0.1, (0.0, TAU), 32, 12, 1.0);
        // A torus encloses its core circle: check against the nearest core point per triangle.
        for t in ring.indices.chunks_exact(3) {
            let p = ring.positions[t[0] as usize];
            let core = c + (p - c).reject_from(Vec3::Y).normalize() * 0.5;
            assert!(ring.normals[t[0] as usize].dot(p - core) > 0.0);
        }
        let sections = [
            Section { y: 0.0, cx: 0.0, cz: 0.0, rx: 0.0, rz: 0.0 },
            Section { y: 0.1, cx: 0.0, cz: 0.0, rx: 0.2, rz: 0.1 },
            Section { y: 0.5, cx: 0.0, cz: 0.05, rx: 0.2, rz: 0.1 },
            Section { y: 0.6, cx: 0.0, cz: 0.05, rx: 0.0, rz: 0.0 },
        ];
        check_outward(&loft(&sections, 16, 12, 1.0), Vec3::new(0.0, 0.3, 0.02));
        let cup =
            Profile::start(0.0, 0.0).line(0.5, 0.0, 2).crease().line(0.5, 1.0, 3).crease().line(0.0, 1.0, 2);
        check_outward(&lathe(&cup, c, 24, 1.0), c + Vec3::Y * 0.5);
        check_outward(&cuboid(Vec3::ZERO, Vec3::new(1.0, 2.0, 3.0), 1.0), Vec3::new(0.5, 1.0, 1.5));
    }

    #[test]
    fn transform_keeps_orientation() {
        let m = sphere(Vec3::ZERO, 1.0, 8, 4);
        let mirrored = m.transformed(Affine3A::from_scale(Vec3::new(-1.0, 1.0, 1.0)));
        check_outward(&mirrored, Vec3::ZERO);
    }
}
