//! Assets and scenes compiled into the binary, so `skin render` needs no files.
//!
//! Head scan: Lee Perry-Smith / Infinite Realities, CC BY 3.0 (`assets/LeePerrySmith_License.txt`).

/// Prefix that names a built-in asset or scene instead of a file.
pub const PREFIX: &str = "builtin:";

/// The default scene: the head three times with per-texel skin (chromophore maps fitted at load
/// to the head's texture; the second and third head's melanin shifted to tan and dark skin), key,
/// fill and rim lights.
pub const THREE_HEADS: &str = include_str!("../assets/scenes/three_heads.toml");

/// The default scene's heads with uniform skin: one chromophore set per head (measured light, tan
/// and dark cheeks), the texture scaling its brightness.
pub const THREE_HEADS_UNIFORM: &str = include_str!("../assets/scenes/three_heads_uniform.toml");

/// A close-up of one ear lit from behind (for transmitted light through thin skin).
pub const EAR: &str = include_str!("../assets/scenes/ear.toml");

/// Fifteen small heads (about 40 pixels tall at 768×384) seen from 10 m: where the level of
/// detail has most to gain.
pub const THREE_HEADS_FAR: &str = include_str!("../assets/scenes/three_heads_far.toml");

/// A close-up of one face with chromophore maps fitted at load (lips, cheeks, stubble).
pub const FACE_MAPS: &str = include_str!("../assets/scenes/face_maps.toml");

/// The same close-up with uniform skin (one chromophore set, the texture scaling its brightness).
pub const FACE: &str = include_str!("../assets/scenes/face.toml");

/// Built-in scene names, the first is the default.
pub const SCENES: [&str; 6] = [
    "three-heads",
    "three-heads-uniform",
    "ear",
    "three-heads-far",
    "face-maps",
    "face",
];

/// The text of a built-in scene by name.
#[must_use]
pub fn scene(name: &str) -> Option<&'static str> {
    match name {
        // `three-heads-maps` is the default scene's earlier name, which scene files may still use.
        "three-heads" | "three-heads-maps" => Some(THREE_HEADS),
        "three-heads-uniform" => Some(THREE_HEADS_UNIFORM),
        "ear" => Some(EAR),
        "three-heads-far" => Some(THREE_HEADS_FAR),
        "face-maps" => Some(FACE_MAPS),
        "face" => Some(FACE),
        _ => None,
    }
}

/// The bytes of a built-in asset by file name.
#[must_use]
pub fn asset(name: &str) -> Option<&'static [u8]> {
    match name {
        "LeePerrySmith.glb" => Some(include_bytes!("../assets/LeePerrySmith.glb")),
        "Map-COL.jpg" => Some(include_bytes!("../assets/Map-COL.jpg")),
        _ => None,
    }
}
