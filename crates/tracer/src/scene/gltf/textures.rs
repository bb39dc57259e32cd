//! glTF textures (glTF 2.0 §3.8, `KHR_texture_transform`): each image a texture refers to is
//! decoded once (`scene::images`) and converted once per colour space it is used in, so two
//! materials sharing an image share its texture whatever their samplers (the sampler lives in
//! the [`TextureRef`]). An image that cannot be read is a warning naming it and the slot using it.

use super::buffers;
use crate::scene::images::{self, ColorSpace};
use crate::texture::{Filter, Texture, TextureRef, Wrap};
use std::collections::HashMap;
use std::path::Path;

/// `KHR_texture_transform` as it appears on a texture reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct UvTransform {
    pub offset: [f32; 2],
    pub rotation: f32,
    pub scale: [f32; 2],
    /// Overrides the reference's `texCoord`.
    pub tex_coord: Option<u32>,
}

/// `EXT_texture_webp`: points every texture that carries the extension at its WebP image (the
/// plain `source`, if any, is the fallback for viewers without WebP). Returns whether anything
/// changed, so the typed document is read again only then.
pub(super) fn use_webp_sources(raw: &mut serde_json::Value) -> bool {
    let Some(textures) = raw.get_mut("textures").and_then(serde_json::Value::as_array_mut) else {
        return false;
    };
    let mut changed = false;
    for texture in textures {
        let webp = texture.pointer("/extensions/EXT_texture_webp/source").cloned();
        if let (Some(source), Some(object)) = (webp, texture.as_object_mut()) {
            object.insert("source".to_owned(), source);
            changed = true;
        }
    }
    changed
}

/// Reads the images glTF textures refer to, each once, and makes the scene's textures.
pub(super) struct TextureLoader<'a> {
    doc: &'a gltf::Document,
    buffers: &'a [Vec<u8>],
    /// The .gltf's folder (relative image URIs resolve against it).
    base: &'a Path,
    /// The glTF file, for messages.
    path: &'a Path,
    /// Decoded images by glTF image index (`None` once decoding failed and was reported).
    decoded: HashMap<usize, Option<image::DynamicImage>>,
    /// Scene texture of each (image, colour space) made so far.
    made: HashMap<(usize, ColorSpace), u32>,
    /// The textures made, in order: `Scene::textures`.
    pub textures: Vec<Texture>,
    /// Warnings, each naming the file.
    pub warnings: Vec<String>,
}

impl<'a> TextureLoader<'a> {
    pub(super) fn new(
        doc: &'a gltf::Document,
        buffers: &'a [Vec<u8>],
        base: &'a Path,
        path: &'a Path,
    ) -> Self {
        Self {
            doc,
            buffers,
            base,
            path,
            decoded: HashMap::new(),
            made: HashMap::new(),
            textures: Vec::new(),
            warnings: Vec::new(),
        }
    }

    /// The document's texture `index`, if there is one.
    pub(super) fn texture(&self, index: usize) -> Option<gltf::Texture<'a>> {
        self.doc.textures().nth(index)
    }

    /// Records a warning about the file.
    pub(super) fn warn(&mut self, message: String) {
        self.warnings.push(format!("{}: {message}", self.path.display()));
    }

    /// "image 2 ('wood.png')" for messages (a data URI is not spelled out).
    fn image_label(&self, image: usize) -> String {
        let json = self.doc.as_json().images.get(image);
        let name = json.and_then(|i| i.name.as_deref()).filter(|n| !n.is_empty());
        let uri = json.and_then(|i| i.uri.as_deref()).filter(|u| !u.starts_with("data:"));
        match name.or(uri) {
            Some(n) => format!("image {image} ('{n}')"),
            None => format!("image {image}"),
        }
    }

    /// The encoded bytes of glTF image `image`: an external file, a data URI, or a buffer view.
    fn image_bytes(&self, image: usize) -> Result<Vec<u8>, String> {
        let json = self.doc.as_json().images.get(image).ok_or("no such image")?;
        match (&json.uri, &json.buffer_view) {
            (Some(uri), _) => buffers::read_uri(uri, self.base).map(|(bytes, _)| bytes),
            (None, Some(view)) => {
                let view = self.doc.views().nth(view.value()).ok_or("its buffer view does not exist")?;
                let b = view.buffer().index();
                let buffer = self.buffers.get(b).ok_or_else(|| format!("buffer {b} is missing"))?;
                view.offset()
                    .checked_add(view.length())
                    .and_then(|end| buffer.get(view.offset()..end))
                    .map(<[u8]>::to_vec)
                    .ok_or_else(|| {
                        format!(
                            "buffer view {} (bytes {}..{}) runs past the end of buffer {b} ({} bytes)",
                            view.index(),
                            view.offset(),
                            view.offset().saturating_add(view.length()),
                            buffer.len()
                        )
                    })
            }
            (None, None) => Err("it has neither a uri nor a bufferView".to_owned()),
        }
    }

    /// The scene texture holding glTF image `image` in `space`, decoding it on first use;
    /// `None` (after one warning per image) when it cannot be read.
    fn texture_of_image(&mut self, image: usize, space: ColorSpace, user: &str) -> Option<u32> {
        if let Some(&t) = self.made.get(&(image, space)) {
            return Some(t);
        }
        if !self.decoded.contains_key(&image) {
            let decoded = self.image_bytes(image).and_then(|bytes| images::decode(&bytes));
            let decoded = match decoded {
                Ok(d) => Some(d),
                Err(m) => {
                    let label = self.image_label(image);
                    self.warn(format!("{label} (used by {user}): {m}; the texture is left out"));
                    None
                }
            };
            self.decoded.insert(image, decoded);
        }
        let decoded = self.decoded.get(&image)?.as_ref()?;
        let space_name = if space == ColorSpace::Srgb { "sRGB" } else { "linear" };
        let name = format!("{}: {} ({space_name})", self.path.display(), self.image_label(image));
        let texture = images::to_texture(name, decoded, space);
        let index = u32::try_from(self.textures.len()).ok()?;
        self.textures.push(texture);
        self.made.insert((image, space), index);
        Some(index)
    }

    /// A material slot's texture reference: the texture's image in `space`, its sampler, the
    /// coordinate set and `KHR_texture_transform`. `user` names the material and slot for
    /// messages. `None` when the image cannot be used (warned).
    pub(super) fn reference(
        &mut self,
        texture: &gltf::Texture,
        tex_coord: u32,
        transform: Option<UvTransform>,
        space: ColorSpace,
        user: &str,
    ) -> Option<TextureRef> {
        let image = texture.source().index();
        let index = self.texture_of_image(image, space, user)?;
        let sampler = texture.sampler();
        let wrap = |mode| match mode {
            gltf::texture::WrappingMode::ClampToEdge => Wrap::ClampToEdge,
            gltf::texture::WrappingMode::MirroredRepeat => Wrap::MirroredRepeat,
            gltf::texture::WrappingMode::Repeat => Wrap::Repeat,
        };
        let filter = match sampler.mag_filter() {
            Some(gltf::texture::MagFilter::Nearest) => Filter::Nearest,
            _ => Filter::Linear,
        };
        let mut uv_set = transform.and_then(|t| t.tex_coord).unwrap_or(tex_coord);
        if uv_set > 1 {
            self.warn(format!(
                "{user} reads TEXCOORD_{uv_set}; only sets 0 and 1 are supported, so set 0 is used"
            ));
            uv_set = 0;
        }
        let transform = transform.and_then(|t| {
            let finite = t.offset.iter().chain(&t.scale).all(|v| v.is_finite()) && t.rotation.is_finite();
            if !finite {
                self.warn(format!("{user}: KHR_texture_transform has a non-finite value; ignored"));
                return None;
            }
            let identity = t.offset == [0.0; 2] && t.rotation == 0.0 && t.scale == [1.0; 2];
            (!identity).then(|| {
                crate::texture::uv_transform(
                    glam::Vec2::from(t.offset),
                    t.rotation,
                    glam::Vec2::from(t.scale),
                )
            })
        });
        Some(TextureRef {
            texture: index,
            uv_set,
            transform,
            wrap: [wrap(sampler.wrap_s()), wrap(sampler.wrap_t())],
            filter,
        })
    }
}
