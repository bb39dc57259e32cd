//! What the remapper tells without failing ([`RemapWarning`]): a region no camera touches,
//! strays treated as background, notes on a layered collage's layers, a collage without
//! background. A leaf: every blend step reports through it.

use crate::regions::RegionInfo;
use crate::stray::StrayReport;
use std::fmt;

/// Something the remapper wants the user to know, without failing.
#[derive(Clone, Debug, PartialEq)]
pub enum RemapWarning {
    /// A region with background pixels holds no edge pixel of any camera: every camera took part.
    RegionWithoutCameras {
        /// Region index.
        region: u32,
        /// Its colour and first pixel.
        info: RegionInfo,
        /// How many background pixels it has.
        background_pixels: usize,
    },
    /// Stray collage pixels were treated as background (by request).
    StraysIgnored(StrayReport),
    /// Something about a layered collage's layers (e.g. one too transparent to take a pixel).
    Layers(String),
    /// The collage has no background pixel: nothing is blended, every pixel keeps its view's
    /// ray, which a collage is rarely meant to do.
    NoBackground,
}

impl fmt::Display for RemapWarning {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::RegionWithoutCameras { region, info, background_pixels } => write!(
                f,
                "region {region} ({info}) touches no camera: its {background_pixels} background pixel(s) \
                 blend all cameras"
            ),
            Self::StraysIgnored(report) => write!(f, "treated as background: {report}"),
            Self::Layers(note) => write!(f, "{note}"),
            Self::NoBackground => write!(
                f,
                "has no background pixel: every pixel is a camera's, so nothing is blended and each keeps \
                 its view's ray; erase (or paint black) where the views should blend"
            ),
        }
    }
}
