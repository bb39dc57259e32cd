//! Generators for the bundled scenes in `scenes/` (a developer tool, not part of mcctrace).
//!
//! - `mcctrace-scenegen cornell DIR` converts the Cornell box's OBJ parts in DIR to glTF 2.0
//!   (`cornell.gltf` + `cornell.bin`), see [`cornell`].
//! - `mcctrace-scenegen cafe DIR` builds the café scene of the MCC column from nothing
//!   (`cafe.gltf` + `cafe.bin`, procedural PNG textures, the collage label and region images),
//!   see [`cafe`]. Every run writes the same bytes.

mod cafe;
mod cornell;
mod gltf_writer;

use anyhow::{Result, bail};
use std::path::Path;

fn main() -> Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.as_slice() {
        [cmd, dir] if cmd == "cornell" => cornell::cornell(Path::new(dir)),
        [cmd, dir] if cmd == "cafe" => cafe::cafe(Path::new(dir)),
        _ => bail!("usage: mcctrace-scenegen (cornell | cafe) DIR"),
    }
}
