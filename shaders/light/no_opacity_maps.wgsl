// No self-shadowing: no fibre lies between any point and any light.
fn hairs_in_front(world: vec3<f32>, slot: i32) -> f32 {
    return 0.0;
}
