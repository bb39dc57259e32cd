//! The café's materials, as Blender's glTF exporter would write them (docs/design/tracer.md §3.10):
//! metallic-roughness factors and textures, `KHR_materials_specular` 0 for pure-Lambertian paint,
//! `KHR_materials_transmission` + `KHR_materials_ior` for glass, and emitters as
//! `emissiveFactor` × `KHR_materials_emissive_strength` (radiance, W·sr⁻¹·m⁻², no π, no 683),
//! one-sided (`doubleSided: false`: they emit from their front face only).

use serde_json::{Value, json};

/// Radiance of the ceiling panel: `PANEL_COLOR` × `PANEL_STRENGTH`.
pub const PANEL_STRENGTH: f64 = 12.0;
pub const PANEL_COLOR: [f64; 3] = [1.0, 0.88, 0.72];
/// Radiance of the daylight "sky" quad outside the window.
pub const SKY_STRENGTH: f64 = 6.0;
pub const SKY_COLOR: [f64; 3] = [0.78, 0.88, 1.0];
/// The drinking glass's wall (m): its `KHR_materials_volume` thickness.
pub const GLASS_WALL: f64 = 0.0025;

/// Indices of the textures (glTF `textures`, in [`super::textures::all`]'s order).
pub mod tex {
    pub const WOOD: usize = 0;
    pub const FLOOR: usize = 1;
    pub const FLOOR_NORMAL: usize = 2;
    pub const KNIT: usize = 3;
    pub const PLAID: usize = 4;
    pub const ZINC_MR: usize = 5;
    pub const PAINTING: usize = 6;
}

/// Every material of the scene; a material's glTF index is its position in [`Mat::ALL`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Mat {
    Plaster,
    WallPaint,
    Ceiling,
    FloorTiles,
    Pavement,
    Wood,
    WoodDark,
    Zinc,
    BlackMetal,
    Steel,
    Gilt,
    Ceramic,
    CeramicTeal,
    Coffee,
    Glass,
    Bottle,
    Leaf,
    PetalRed,
    PetalYellow,
    SkinA,
    SkinB,
    Lips,
    HairA,
    HairB,
    Eye,
    SweaterA,
    DressB,
    TrousersA,
    TightsB,
    Shoes,
    WindowFrame,
    Painting,
    Enamel,
    LampPanel,
    Sky,
}

impl Mat {
    pub const ALL: [Mat; 35] = [
        Mat::Plaster,
        Mat::WallPaint,
        Mat::Ceiling,
        Mat::FloorTiles,
        Mat::Pavement,
        Mat::Wood,
        Mat::WoodDark,
        Mat::Zinc,
        Mat::BlackMetal,
        Mat::Steel,
        Mat::Gilt,
        Mat::Ceramic,
        Mat::CeramicTeal,
        Mat::Coffee,
        Mat::Glass,
        Mat::Bottle,
        Mat::Leaf,
        Mat::PetalRed,
        Mat::PetalYellow,
        Mat::SkinA,
        Mat::SkinB,
        Mat::Lips,
        Mat::HairA,
        Mat::HairB,
        Mat::Eye,
        Mat::SweaterA,
        Mat::DressB,
        Mat::TrousersA,
        Mat::TightsB,
        Mat::Shoes,
        Mat::WindowFrame,
        Mat::Painting,
        Mat::Enamel,
        Mat::LampPanel,
        Mat::Sky,
    ];

    pub fn index(self) -> usize {
        Mat::ALL.iter().position(|&m| m == self).expect("every material is listed in ALL")
    }

    /// Whether the material reads `TEXCOORD_0` (so its primitives carry texture coordinates).
    pub fn textured(self) -> bool {
        self.def().textures.iter().any(Option::is_some)
    }

    /// Whether the material has a normal map (so its primitives carry tangents).
    pub fn normal_mapped(self) -> bool {
        self.def().textures[2].is_some()
    }

    fn def(self) -> Def {
        use Mat::*;
        let d = Def::diffuse;
        match self {
            Plaster => d("plaster", [0.70, 0.62, 0.50]).rough(1.0).matte(),
            WallPaint => d("wall_paint_green", [0.035, 0.10, 0.065]).rough(0.45),
            Ceiling => d("ceiling", [0.75, 0.73, 0.69]).rough(1.0).matte(),
            FloorTiles => {
                d("floor_tiles", [1.0; 3]).rough(0.28).tex(Some(tex::FLOOR), None, Some(tex::FLOOR_NORMAL))
            }
            Pavement => d("pavement", [0.30, 0.29, 0.27]).rough(0.9),
            Wood => d("wood", [1.0; 3]).rough(0.38).tex(Some(tex::WOOD), None, None),
            WoodDark => d("wood_dark", [0.45, 0.40, 0.38]).rough(0.42).tex(Some(tex::WOOD), None, None),
            Zinc => d("zinc", [0.80, 0.81, 0.83]).metal(1.0).rough(1.0).tex(None, Some(tex::ZINC_MR), None),
            BlackMetal => d("black_painted_metal", [0.025, 0.025, 0.028]).rough(0.35),
            Steel => d("steel", [0.90, 0.90, 0.91]).metal(1.0).rough(0.12),
            Gilt => d("gilt", [0.88, 0.62, 0.28]).metal(1.0).rough(0.35),
            Ceramic => d("ceramic_white", [0.86, 0.85, 0.81]).rough(0.06),
            CeramicTeal => d("ceramic_teal", [0.04, 0.22, 0.25]).rough(0.08),
            Coffee => d("coffee", [0.055, 0.022, 0.008]).rough(0.02),
            Glass => d("glass", [1.0; 3]).rough(0.0).glass(),
            Bottle => d("bottle_green", [0.015, 0.06, 0.025]).rough(0.03),
            Leaf => d("leaf", [0.04, 0.16, 0.03]).rough(0.5),
            PetalRed => d("petal_red", [0.70, 0.05, 0.07]).rough(0.55),
            PetalYellow => d("petal_yellow", [0.80, 0.55, 0.06]).rough(0.55),
            SkinA => d("skin_a", [0.68, 0.41, 0.29]).rough(0.5),
            SkinB => d("skin_b", [0.34, 0.18, 0.105]).rough(0.5),
            Lips => d("lips", [0.30, 0.08, 0.07]).rough(0.35),
            HairA => d("hair_a", [0.018, 0.013, 0.009]).rough(0.35),
            HairB => d("hair_b", [0.22, 0.06, 0.022]).rough(0.35),
            Eye => d("eye", [0.012, 0.010, 0.009]).rough(0.04),
            SweaterA => d("sweater_a", [0.13, 0.26, 0.62]).rough(0.95).tex(Some(tex::KNIT), None, None),
            DressB => d("dress_b", [1.0; 3]).rough(0.85).tex(Some(tex::PLAID), None, None),
            TrousersA => d("trousers_a", [0.05, 0.05, 0.06]).rough(0.8),
            TightsB => d("tights_b", [0.025, 0.02, 0.025]).rough(0.6),
            Shoes => d("shoes", [0.05, 0.025, 0.012]).rough(0.3),
            WindowFrame => d("window_frame", [0.78, 0.78, 0.75]).rough(0.4),
            Painting => d("painting", [1.0; 3]).rough(0.7).tex(Some(tex::PAINTING), None, None),
            Enamel => d("enamel_green", [0.03, 0.16, 0.09]).rough(0.25),
            LampPanel => d("ceiling_panel", [0.8; 3]).rough(1.0).emit(PANEL_COLOR, PANEL_STRENGTH),
            Sky => d("sky", [0.0; 3]).rough(1.0).emit(SKY_COLOR, SKY_STRENGTH),
        }
    }

    /// The glTF material object.
    pub fn json(self) -> Value {
        let d = self.def();
        let [r, g, b] = d.base;
        let mut m = json!({
            "name": d.name,
            "pbrMetallicRoughness": {
                "baseColorFactor": [r, g, b, 1.0],
                "metallicFactor": d.metallic,
                "roughnessFactor": d.roughness,
            },
            "doubleSided": d.emission.is_none(),
        });
        let [base, mr, normal] = d.textures;
        if let Some(t) = base {
            m["pbrMetallicRoughness"]["baseColorTexture"] = json!({ "index": t, "texCoord": 0 });
        }
        if let Some(t) = mr {
            m["pbrMetallicRoughness"]["metallicRoughnessTexture"] = json!({ "index": t, "texCoord": 0 });
        }
        if let Some(t) = normal {
            m["normalTexture"] = json!({ "index": t, "texCoord": 0, "scale": 1.0 });
        }
        let mut ext = serde_json::Map::new();
        if d.matte {
            ext.insert("KHR_materials_specular".into(), json!({ "specularFactor": 0.0 }));
        }
        if d.glass {
            ext.insert("KHR_materials_transmission".into(), json!({ "transmissionFactor": 1.0 }));
            ext.insert("KHR_materials_ior".into(), json!({ "ior": 1.5 }));
            // The glass is a closed solid (the tumbler's walls are 2.5 mm thick): without a
            // volume the glTF specification would read its surfaces as thin walls that do not
            // refract.
            ext.insert("KHR_materials_volume".into(), json!({ "thicknessFactor": GLASS_WALL }));
        }
        if let Some((color, strength)) = d.emission {
            m["emissiveFactor"] = json!(color);
            ext.insert("KHR_materials_emissive_strength".into(), json!({ "emissiveStrength": strength }));
        }
        if !ext.is_empty() {
            m["extensions"] = Value::Object(ext);
        }
        m
    }

    /// The extensions this material uses.
    pub fn extensions(self) -> Vec<&'static str> {
        let d = self.def();
        let mut out = Vec::new();
        if d.matte {
            out.push("KHR_materials_specular");
        }
        if d.glass {
            out.extend(["KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume"]);
        }
        if d.emission.is_some() {
            out.push("KHR_materials_emissive_strength");
        }
        out
    }

    /// The base colour factor (linear), for previews.
    #[cfg(test)]
    pub fn base_color(self) -> [f64; 3] {
        self.def().base
    }

    /// The emitted radiance, for previews.
    #[cfg(test)]
    pub fn emission(self) -> Option<[f64; 3]> {
        self.def().emission.map(|(c, s)| c.map(|v| v * s))
    }
}

/// A material's definition.
struct Def {
    name: &'static str,
    base: [f64; 3],
    metallic: f64,
    roughness: f64,
    /// Base colour, metallic-roughness, normal.
    textures: [Option<usize>; 3],
    matte: bool,
    glass: bool,
    emission: Option<([f64; 3], f64)>,
}

impl Def {
    fn diffuse(name: &'static str, base: [f64; 3]) -> Def {
        Def {
            name,
            base,
            metallic: 0.0,
            roughness: 0.5,
            textures: [None; 3],
            matte: false,
            glass: false,
            emission: None,
        }
    }
    fn rough(self, roughness: f64) -> Def {
        Def { roughness, ..self }
    }
    fn metal(self, metallic: f64) -> Def {
        Def { metallic, ..self }
    }
    /// Pure Lambertian (no specular layer), as Blender writes plain walls.
    fn matte(self) -> Def {
        Def { matte: true, ..self }
    }
    fn glass(self) -> Def {
        Def { glass: true, ..self }
    }
    fn tex(self, base: Option<usize>, mr: Option<usize>, normal: Option<usize>) -> Def {
        Def { textures: [base, mr, normal], ..self }
    }
    fn emit(self, color: [f64; 3], strength: f64) -> Def {
        Def { emission: Some((color, strength)), ..self }
    }
}
