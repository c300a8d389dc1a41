use super::*;
use crate::model::mesh::test_meshes::grid;
use crate::strands::reference::{StrandOptions, generate};

fn grid_cards(options: &CardOptions) -> (Document, Vec<Strand>, HairCards) {
    let mut document = Document::new("grid", grid(3, 2, 3, 0.5));
    // Curls carry strands beyond their bundle: the cards must widen to hold them.
    document.styling.global.curl.radius_m = 0.3;
    document.styling.global.curl.turns_per_m = 1.0;
    let strands = generate(
        &document,
        &StrandOptions {
            strands_per_bundle: 24,
            vertices_log2: 4,
            ..StrandOptions::default()
        },
    );
    let cards = hair_cards(&document, &strands, options);
    (document, strands, cards)
}

#[test]
fn every_bundle_becomes_a_card_with_its_strands_inside() {
    let (document, strands, cards) = grid_cards(&CardOptions::default());
    let bundles = document.hair_mesh.bundles.len();
    assert_eq!(cards.cards, bundles);
    assert_eq!(
        cards.baked_points,
        strands.iter().map(|s| s.points.len()).sum::<usize>()
    );
    // Levels: 4, 2 and 1 segments per layer, two triangles each.
    let layers: usize = document
        .hair_mesh
        .bundles
        .iter()
        .map(|b| b.layers as usize)
        .sum();
    let triangles: Vec<usize> = cards.levels.iter().map(CardMesh::triangles).collect();
    assert_eq!(triangles, [8 * layers, 4 * layers, 2 * layers]);
    for level in &cards.levels {
        assert_eq!(level.positions.len(), level.uvs.len());
        assert!(
            level
                .indices
                .iter()
                .all(|&i| (i as usize) < level.positions.len())
        );
        assert!(level.positions.iter().flatten().all(|c| c.is_finite()));
        assert!(
            level
                .uvs
                .iter()
                .flatten()
                .all(|&c| (0.0..=1.0).contains(&c))
        );
        assert!(
            level
                .normals
                .iter()
                .all(|n| (Vec3::from(*n).length() - 1.0).abs() < 1e-4)
        );
    }
    // Every card's tile has strands in it, and nothing is drawn between tiles' edges that
    // no card covers.
    let atlas = &cards.atlas;
    assert_eq!(
        atlas.albedo.len(),
        (atlas.width * atlas.height * 4) as usize
    );
    let [tw, th] = CardOptions::default().tile_px;
    let columns = (atlas.width / tw) as usize;
    for c in 0..cards.cards {
        let (x0, y0) = ((c % columns) as u32 * tw, (c / columns) as u32 * th);
        let covered = (y0..y0 + th)
            .flat_map(|y| (x0..x0 + tw).map(move |x| (y * atlas.width + x) as usize))
            .filter(|&i| atlas.coverage[i] > 0)
            .count();
        assert!(
            covered > (tw * th / 8) as usize,
            "card {c}: {covered} texels covered"
        );
    }
    for c in cards.cards..columns * (atlas.height / th) as usize {
        let (x0, y0) = ((c % columns) as u32 * tw, (c / columns) as u32 * th);
        assert!(
            (y0..y0 + th)
                .flat_map(|y| (x0..x0 + tw).map(move |x| (y * atlas.width + x) as usize))
                .all(|i| atlas.coverage[i] == 0),
            "empty tile {c} has coverage"
        );
    }
    // Albedo alpha is the coverage; root-to-tip grows down the tile.
    assert!(
        atlas
            .coverage
            .iter()
            .zip(atlas.albedo.chunks_exact(4))
            .all(|(&c, rgba)| rgba[3] == c)
    );
    let mean_row = |y: u32| -> f64 {
        let row = (0..tw).map(|x| atlas.root_to_tip[(y * atlas.width + x) as usize] as f64);
        row.sum::<f64>() / tw as f64
    };
    assert!(mean_row(th - 8) > mean_row(8) + 100.0);
}

#[test]
fn a_collapsed_bundle_and_no_strands_still_give_finite_cards() {
    let mut document = Document::new("grid", grid(2, 1, 2, 0.5));
    // Collapse the first bundle's root face onto one point and its columns onto one line.
    let corners = document.hair_mesh.bundles[0].vertices.clone();
    let target = document.hair_mesh.columns[corners[0] as usize].clone();
    for &c in &corners {
        document.hair_mesh.columns[c as usize] = target.clone();
    }
    let cards = hair_cards(&document, &[], &CardOptions::default());
    assert_eq!(cards.baked_points, 0);
    assert!(cards.atlas.coverage.iter().all(|&c| c == 0));
    for level in &cards.levels {
        assert!(level.positions.iter().flatten().all(|c| c.is_finite()));
        assert!(level.normals.iter().flatten().all(|c| c.is_finite()));
    }
    // Many more cards than one atlas row holds at the asked tile size: tiles shrink to fit.
    let small = CardOptions {
        max_atlas_px: 256,
        ..CardOptions::default()
    };
    let many = hair_cards(&Document::new("grid", grid(40, 40, 1, 0.1)), &[], &small);
    assert_eq!(many.cards, 1600);
    assert!(many.atlas.width <= 256 && many.atlas.height <= 256);
    let [tw, th] = [many.atlas.width, many.atlas.height];
    assert!(tw * th >= 1600 * 2 * 2, "{tw}×{th} cannot hold 1,600 tiles");
}

/// Unreal's card textures come from the same bake: where strands cover a texel, the
/// attribute texture holds the nearest strand's root uv (one of the bundle's strands),
/// its seed (the id map) and the coordinate along it (the root-to-tip map); the tangent
/// texture is the flow with 0 out of the card.
#[test]
fn unreal_card_textures_carry_root_uv_coordinate_and_seed() {
    let (_, strands, cards) = grid_cards(&CardOptions::default());
    let atlas = &cards.atlas;
    let [depth, coverage, tangent, attribute] = atlas.unreal_textures();
    assert_eq!(depth.2, atlas.depth);
    assert_eq!(coverage.2, atlas.coverage);
    let texels = (atlas.width * atlas.height) as usize;
    assert_eq!((tangent.1, tangent.2.len()), (3, 3 * texels));
    assert_eq!((attribute.1, attribute.2.len()), (4, 4 * texels));
    let mut covered = 0;
    for i in (0..texels).filter(|&i| atlas.coverage[i] > 0) {
        covered += 1;
        let a = &attribute.2[4 * i..4 * i + 4];
        assert_eq!((a[2], a[3]), (atlas.root_to_tip[i], atlas.id[i]));
        let uv = [a[0] as f64 / 255.0, a[1] as f64 / 255.0];
        assert!(
            strands
                .iter()
                .any(|s| (s.root_uv.x - uv[0]).abs() <= 0.5 / 255.0 + 1e-9
                    && (s.root_uv.y - uv[1]).abs() <= 0.5 / 255.0 + 1e-9),
            "texel {i}: root uv {uv:?} is no strand's"
        );
        assert_eq!(
            &tangent.2[3 * i..3 * i + 3],
            &[atlas.flow[3 * i], atlas.flow[3 * i + 1], 128]
        );
    }
    assert!(covered > 100, "{covered} covered texels");
}
