// Deep opacity maps: the layers start at the first hair each texel sees, from the depth pass
// (no hair in the texel: the far plane, so nothing there is shadowed).
@group(2) @binding(1) var first_hair_depth: texture_depth_2d_array;

fn first_hair_distance(slot: u32, texel: vec2<i32>) -> f32 {
    let z = textureLoad(first_hair_depth, texel, i32(slot), 0);
    return light_distance(z, scene.shadows[slot].params);
}
