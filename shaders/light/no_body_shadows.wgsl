// No body shadows: the body never blocks a light.
fn body_visibility(world: vec3<f32>, slot: i32) -> f32 {
    return 1.0;
}

fn body_surface_visibility(world: vec3<f32>, normal: vec3<f32>, slot: i32) -> f32 {
    return 1.0;
}
