//! The slanted-edge scene of `tests/render_camera.rs` and `examples/edge_mtf.rs`.

/// A hot plate whose edge crosses the image centre 5° from the vertical, seen straight down from
/// 50 m against a black ground at 260 K (open world: no noise, no occlusion).
pub fn slanted_edge_scene(optics: &str) -> String {
    let angle = 5f64.to_radians();
    format!(
        "[camera]\nposition = [0.0, 0.0, 50.0]\nlook_at = [0.0, 0.0, 0.0]\nup = [0.0, 1.0, 0.0]\n\
         fov_deg = 3.0\nresolution = [160, 160]\n\n\
         [sensor]\nnetd_reference_k = 300.0\n{optics}\n\
         [environment]\nair_temperature_k = 283.15\n\
         sky = {{ model = \"window\", zenith_emissivity = 0.75 }}\n\
         ground = {{ temperature_k = 260.0, emissivity = 1.0 }}\n\n\
         [render]\nopen_world = true\n\n\
         [materials.m]\ndistribution = \"cauchy\"\nsigma = 0.3\nq = 2.0\nn = 1.5\nk = 0.05\n\
         rho_d = 0.0\nshadowing = \"smith\"\n\n\
         [[objects]]\nname = \"plate\"\nshape = {{ kind = \"plane\", size = [40.0, 40.0], divisions = [1, 1] }}\n\
         material = \"m\"\ntemperature_k = 330.0\nrotate_deg = [0.0, 0.0, 5.0]\n\
         translate = [{}, {}, 0.0]\n",
        20.0 * angle.cos(),
        20.0 * angle.sin(),
    )
}
