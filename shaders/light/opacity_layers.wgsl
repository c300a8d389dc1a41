// Where opacity-map layers lie: distances from a shadow-casting light and layer ends
// (opacity shadow maps: even over the hair's depth; deep opacity maps: quadratic behind the
// first hair). Shared by the lookups (opacity_maps.wgsl) and the passes that fill the maps
// (hair_shadow.wgsl). CPU mirror (same names): core/src/light/opacity_maps.rs.

fn light_distance(z: f32, params: vec4<f32>) -> f32 {
    let near = params.x;
    let far = params.y;
    if params.z != 0.0 {
        return near * far / max(far - z * (far - near), 1e-12);
    }
    return near + z * (far - near);
}

fn layer_end(k: u32, layers: u32, start: f32, depth: f32) -> f32 {
    let fraction = f32(k + 1u) / f32(max(layers, 1u));
    if scene.counts.z == 2u {
        return start + depth * fraction * fraction;
    }
    return start + depth * fraction;
}

