// Opacity shadow maps: the layers start at the view's near plane everywhere.
fn first_hair_distance(slot: u32, texel: vec2<i32>) -> f32 {
    return scene.shadows[slot].params.x;
}
