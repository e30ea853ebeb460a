//! Rays, bounds, robust offsets and the analytic shapes.

pub mod bounds;
pub mod ray;
pub mod shapes;

pub use bounds::Aabb;
pub use ray::{Ray, offset_ray_origin, offset_ray_origin_lanes, spawn_ray, spawn_ray_to};
pub use shapes::{OrientedBox, Planar, ShapeSample, Sphere, SurfacePoint};
pub mod motion;
pub use motion::RigidMotion;
pub mod revolution;
pub use revolution::{Revolution, RevolutionHit, RevolutionStats};
pub mod mesh;
pub mod mesh_io;
pub use mesh::{MeshHit, TriangleMesh};
