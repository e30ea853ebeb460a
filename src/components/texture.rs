//! `Texture`: an albedo source (image or procedural), an optional normal map, and the UV
//! mapping.
//!
//! ```
//! # use prism::scene_file::schema::TextureSpec;
//! let t: TextureSpec = ron::from_str(
//!     "(albedo: Some(Bricks(brick: Rgb(0.5, 0.15, 0.1), mortar: Rgb(0.8, 0.8, 0.75), size: (0.4, 0.2))),
//!       normal_map: Some(FromHeight(strength: 1.0)), scale: Some((2.0, 2.0)))",
//! ).unwrap();
//! # let _ = t;
//! ```
//! A texture modulates Diffuse albedo, Mirror tint or Light emission; on a Dielectric only its
//! normal map applies. UVs per shape: spheres longitude/latitude (u = 0.5 at +z, v = 0 at the
//! south pole, in the sphere's rotated frame), rects and disks their (u, v) axes over [0, 1],
//! boxes planar per face, meshes their file's UVs.

pub use crate::texture::Texture;
