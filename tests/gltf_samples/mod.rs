//! The Khronos glTF sample models (`../shared/gltf-samples/`, beside the repository; CI keeps a
//! copy there): what each model's README says a correct render shows, checked on the loaded
//! scene. The models are read in place, never copied into the repository.

mod corpus;
mod lighting;
mod lobes;
mod texture_transform;
mod vertex_colors;

use std::path::PathBuf;

/// `../shared/gltf-samples/NAME/glTF/NAME.gltf`, or a panic saying where the models belong.
pub(crate) fn sample(name: &str) -> PathBuf {
    let root = crate::common::repo_root().join("../shared/gltf-samples");
    assert!(
        root.is_dir(),
        "{}: the Khronos glTF sample models are missing (a copy of shared/gltf-samples belongs beside the \
         repository)",
        root.display()
    );
    root.join(name).join("glTF").join(format!("{name}.gltf"))
}
