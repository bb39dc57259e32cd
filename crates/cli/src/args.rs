//! Value parsers for command-line arguments: vectors, colours and resolutions.

use glam::{UVec2, Vec3};
use std::str::FromStr;

/// A 3-vector written `x,y,z`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Vec3Arg(pub Vec3);

impl FromStr for Vec3Arg {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let parts: Vec<&str> = s.split(',').map(str::trim).collect();
        if parts.len() != 3 {
            return Err(format!("'{s}' is not three comma-separated numbers (like 1,2.5,-3)"));
        }
        let mut v = [0.0f32; 3];
        for (slot, p) in v.iter_mut().zip(&parts) {
            *slot = p.parse::<f32>().map_err(|_| format!("'{p}' in '{s}' is not a number"))?;
            if !slot.is_finite() {
                return Err(format!("'{p}' in '{s}' is not finite"));
            }
        }
        Ok(Self(Vec3::from_array(v)))
    }
}

/// An image size written `WIDTHxHEIGHT`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Resolution(pub UVec2);

impl FromStr for Resolution {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        let (w, h) =
            s.split_once(['x', 'X']).ok_or_else(|| format!("'{s}' is not WIDTHxHEIGHT (like 640x360)"))?;
        let parse =
            |v: &str| v.trim().parse::<u32>().map_err(|_| format!("'{v}' in '{s}' is not a whole number"));
        let (w, h) = (parse(w)?, parse(h)?);
        if w == 0 || h == 0 {
            return Err(format!("'{s}' has a zero dimension"));
        }
        Ok(Self(UVec2::new(w, h)))
    }
}

impl std::fmt::Display for Resolution {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}x{}", self.0.x, self.0.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_refuses() {
        assert_eq!("1, 2.5,-3".parse::<Vec3Arg>().unwrap().0, Vec3::new(1.0, 2.5, -3.0));
        assert!("1,2".parse::<Vec3Arg>().is_err());
        assert!("1,nan,2".parse::<Vec3Arg>().is_err());
        assert_eq!("640x360".parse::<Resolution>().unwrap().0, UVec2::new(640, 360));
        assert!("640".parse::<Resolution>().is_err());
        assert!("0x10".parse::<Resolution>().is_err());
        assert!("-5x10".parse::<Resolution>().is_err());
    }
}
