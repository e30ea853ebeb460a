//! Point and spot lights against their closed-form irradiance.

mod common;
use common::render::{image, mean_where};

fn plane_under(light: &str) -> String {
    format!(
        r#"Scene(
    render: (width: 33, height: 33, spp: 4, max_depth: 3, seed: 1),
    camera: (position: (0.0, 5.0, 0.0), look_at: (0.0, 0.0, 0.0), up: (0.0, 0.0, -1.0), fov_y: 60.0),
    entities: [
        (name: "light", light: {light}),
        (name: "plane", shape: Rect(center: (0.0, 0.0, 0.0), u: (10.0, 0.0, 0.0), v: (0.0, 0.0, -10.0)),
         material: Diffuse(albedo: Rgb(0.5, 0.5, 0.5))),
    ],
)"#
    )
}

#[test]
fn a_point_light_gives_intensity_over_distance_squared() {
    // Radiance of a Lambertian plane of albedo ρ straight under a point light of intensity I
    // at height h: ρ/π · I/h². The centre pixel sees the point under the light; the tent
    // filter spreads over ±1 px, where cos³θ/h² changes by < 0.1 %.
    let img = image(&plane_under(
        "Point(position: (0.0, 2.0, 0.0), intensity: Rgb(8.0, 8.0, 8.0))",
    ));
    let expect = 0.5 / std::f64::consts::PI * 8.0 / 4.0;
    let m = mean_where(&img, 1, |x, y| x == 16 && y == 16);
    assert!((m / expect - 1.0).abs() < 0.005, "{m} vs {expect}");
}

#[test]
fn a_spot_light_is_full_inside_its_cone_and_dark_outside() {
    let spot = "Spot(position: (0.0, 2.0, 0.0), direction: (0.0, -1.0, 0.0), cone: 20.0, falloff: 5.0, intensity: Rgb(8.0, 8.0, 8.0))";
    let img = image(&plane_under(spot));
    let expect = 0.5 / std::f64::consts::PI * 8.0 / 4.0;
    let centre = mean_where(&img, 1, |x, y| x == 16 && y == 16);
    assert!(
        (centre / expect - 1.0).abs() < 0.005,
        "{centre} vs {expect}"
    );
    // The corner pixels see plane points about 4 units from the axis, 63° off the spot's axis
    // from the light: far outside its 20° cone.
    let corner = mean_where(&img, 1, |x, y| x < 4 && y < 4);
    assert_eq!(corner, 0.0);
}
