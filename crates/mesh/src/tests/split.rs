use super::*;
use crate::Element;

fn tet(vertices: [u32; 4]) -> Element {
    Element {
        kind: Shape::Tet,
        vertices: vertices.to_vec(),
        entity: 1,
    }
}

/// Two tetrahedra sharing the face 0 1 2, and a facet on edge 0 1.
fn pair() -> LinearMesh {
    LinearMesh {
        dim: 3,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ],
        cells: vec![tet([0, 1, 2, 3]), tet([0, 2, 1, 4])],
        facets: vec![Element {
            kind: Shape::Tri,
            vertices: vec![0, 1, 3],
            entity: 7,
        }],
        ..Default::default()
    }
}

fn volume(mesh: &LinearMesh, e: &Element) -> f64 {
    let x: Vec<[f64; 3]> = e
        .vertices
        .iter()
        .map(|&v| mesh.vertices[v as usize])
        .collect();
    let d = |i: usize| [x[i][0] - x[0][0], x[i][1] - x[0][1], x[i][2] - x[0][2]];
    let (a, b, c) = (d(1), d(2), d(3));
    (a[0] * (b[1] * c[2] - b[2] * c[1]) - a[1] * (b[0] * c[2] - b[2] * c[0])
        + a[2] * (b[0] * c[1] - b[1] * c[0]))
        / 6.0
}

#[test]
fn splitting_an_edge_halves_every_simplex_around_it_and_keeps_volume_and_orientation() {
    let mesh = pair();
    let before: f64 = mesh.cells.iter().map(|c| volume(&mesh, c)).sum();
    let (split, count) = mesh.split_edges(&[[0, 1]]);
    assert_eq!(count, 1);
    assert_eq!(split.vertices.len(), 6);
    assert_eq!(split.vertices[5], [0.5, 0.0, 0.0]);
    assert_eq!(split.cells.len(), 4);
    assert_eq!(split.facets.len(), 2);
    let after: f64 = split.cells.iter().map(|c| volume(&split, c)).sum();
    assert!((before - after).abs() < 1e-15);
    for c in &split.cells {
        assert!(volume(&split, c) > 0.0, "{c:?}");
        assert!(!(c.vertices.contains(&0) && c.vertices.contains(&1)));
    }
    assert!(split.facets.iter().all(|f| f.entity == 7));
    assert!(split.validate().is_ok());
    assert!(split.check_orientation().is_ok());
}

#[test]
fn a_split_vertex_goes_where_it_is_asked_to() {
    let mesh = pair();
    let (split, count) = mesh.split_edges_at(&[([0, 1], Some([0.5, -0.1, 0.0])), ([2, 3], None)]);
    assert_eq!(count, 2);
    assert_eq!(split.vertices[5], [0.5, -0.1, 0.0]);
    assert_eq!(split.vertices[6], [0.0, 0.5, 0.5]);
    assert_eq!(split.facets.len(), 2, "the facet 0 1 3 holds edge 0 1 only");
}

#[test]
fn edges_that_do_not_exist_or_touch_non_simplices_are_not_split() {
    let mesh = pair();
    let (same, count) = mesh.split_edges(&[[3, 4]]);
    assert_eq!(count, 0);
    assert_eq!(same, mesh);
    let mut mixed = mesh.clone();
    mixed.cells.push(Element {
        kind: Shape::Hex,
        vertices: vec![0, 1, 5, 6, 7, 8, 9, 10],
        entity: 1,
    });
    let (_, count) = mixed.split_edges(&[[0, 1]]);
    assert_eq!(count, 0);
    // The second of two overlapping requests is gone once the first is split.
    let (_, count) = mesh.split_edges(&[[0, 1], [1, 0]]);
    assert_eq!(count, 1);
}

#[test]
fn a_quadrilateral_splits_into_two_positive_triangles_along_the_diagonal_of_its_corner() {
    let quad = LinearMesh {
        dim: 2,
        vertices: vec![
            [0.0, 0.0, 0.0],
            [2.0, 0.0, 0.0],
            [2.5, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        cells: vec![Element {
            kind: Shape::Quad,
            vertices: vec![0, 1, 2, 3],
            entity: 4,
        }],
        cell_tags: vec![10],
        facet_tags: vec![],
        ..Default::default()
    };
    let area = |m: &LinearMesh, e: &Element| {
        let x: Vec<[f64; 3]> = e.vertices.iter().map(|&v| m.vertices[v as usize]).collect();
        (x[1][0] - x[0][0]) * (x[2][1] - x[0][1]) - (x[1][1] - x[0][1]) * (x[2][0] - x[0][0])
    };
    for corner in 0..4 {
        let (split, count) = quad.split_quadrilaterals(&[(0, corner)]);
        assert_eq!(count, 1);
        assert_eq!(split.cells.len(), 2);
        assert!(split
            .cells
            .iter()
            .all(|c| c.kind == Shape::Tri && c.entity == 4));
        assert!(
            split.cells.iter().all(|c| area(&split, c) > 0.0),
            "corner {corner}"
        );
        // Both triangles hold the corner and the opposite vertex: the diagonal.
        let (a, b) = (corner as u32, ((corner + 2) % 4) as u32);
        assert!(split
            .cells
            .iter()
            .all(|c| c.vertices.contains(&a) && c.vertices.contains(&b)));
        let total: f64 = split.cells.iter().map(|c| area(&split, c)).sum();
        // Twice the area (shoelace): 2 × 2.25.
        assert!((total - 4.5).abs() < 1e-12, "{total}");
        assert_eq!(split.cell_tags, vec![10, 11]);
    }
    // Not a quadrilateral: nothing happens.
    let (same, count) = pair().split_quadrilaterals(&[(0, 1)]);
    assert_eq!(count, 0);
    assert_eq!(same.cells.len(), 2);
}

/// The plain statement of `split_edges_at`: every element scanned for each edge.
fn split_by_scanning(mesh: &LinearMesh, edges: &[([u32; 2], Option<[f64; 3]>)]) -> LinearMesh {
    let mut mesh = mesh.clone();
    for &([a, b], position) in edges {
        let holds = |e: &Element| e.vertices.contains(&a) && e.vertices.contains(&b);
        let any = mesh.cells.iter().chain(&mesh.facets).any(holds);
        let simplices = mesh
            .cells
            .iter()
            .chain(&mesh.facets)
            .filter(|e| holds(e))
            .all(|e| matches!(e.kind, Shape::Tri | Shape::Tet | Shape::Line));
        if a == b || !any || !simplices {
            continue;
        }
        let m = mesh.vertices.len() as u32;
        let (pa, pb) = (mesh.vertices[a as usize], mesh.vertices[b as usize]);
        mesh.vertices
            .push(position.unwrap_or([0, 1, 2].map(|d| 0.5 * (pa[d] + pb[d]))));
        let (c0, f0) = (mesh.cells.len(), mesh.facets.len());
        for list in [&mut mesh.cells, &mut mesh.facets] {
            let mut second = Vec::new();
            for e in list.iter_mut().filter(|e| holds(e)) {
                let mut other = e.clone();
                e.vertices
                    .iter_mut()
                    .filter(|v| **v == b)
                    .for_each(|v| *v = m);
                other
                    .vertices
                    .iter_mut()
                    .filter(|v| **v == a)
                    .for_each(|v| *v = m);
                second.push(other);
            }
            list.extend(second);
        }
        let next = mesh.vertex_tags.iter().max().map_or(1, |t| t + 1);
        mesh.vertex_tags.push(next);
        let next = mesh
            .cell_tags
            .iter()
            .chain(&mesh.facet_tags)
            .max()
            .map_or(1, |t| t + 1);
        let added_cells = (mesh.cells.len() - c0) as u64;
        mesh.cell_tags.extend(next..next + added_cells);
        let added_facets = (mesh.facets.len() - f0) as u64;
        mesh.facet_tags
            .extend(next + added_cells..next + added_cells + added_facets);
    }
    mesh
}

/// An edge and where to split it.
type SplitAt = ([u32; 2], Option<[f64; 3]>);

/// A 3 × 3 × 3 block of Kuhn-split cubes with its bottom triangles as facets, and a list of
/// edges to split.
fn kuhn_block_and_edges() -> (LinearMesh, Vec<SplitAt>) {
    // A 3 × 3 × 3 block of cubes, six tetrahedra each (Kuhn), the bottom face's triangles as
    // facets, with tags out of order.
    let n = 3;
    let id = |i: usize, j: usize, k: usize| ((i * (n + 1) + j) * (n + 1) + k) as u32;
    let mut mesh = LinearMesh {
        dim: 3,
        ..Default::default()
    };
    for i in 0..=n {
        for j in 0..=n {
            for k in 0..=n {
                mesh.vertices.push([i as f64, j as f64, k as f64]);
                mesh.vertex_tags
                    .push((7 * mesh.vertex_tags.len() as u64 + 3) % 101 + 1);
            }
        }
    }
    let paths = [
        [0, 1, 2],
        [0, 2, 1],
        [1, 0, 2],
        [1, 2, 0],
        [2, 0, 1],
        [2, 1, 0],
    ];
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                for axes in paths {
                    let mut at = [i, j, k];
                    let mut corners = vec![id(at[0], at[1], at[2])];
                    for a in axes {
                        at[a] += 1;
                        corners.push(id(at[0], at[1], at[2]));
                    }
                    let mut cell = tet([corners[0], corners[1], corners[2], corners[3]]);
                    // (Odd permutations of the axes turn the other way.)
                    if volume(&mesh, &cell) < 0.0 {
                        cell.vertices.swap(2, 3);
                    }
                    mesh.cells.push(cell);
                }
            }
            if i < n && j < n {
                let (a, b, c, d) = (
                    id(i, j, 0),
                    id(i + 1, j, 0),
                    id(i + 1, j + 1, 0),
                    id(i, j + 1, 0),
                );
                for v in [vec![a, c, b], vec![a, d, c]] {
                    mesh.facets.push(Element {
                        kind: Shape::Tri,
                        vertices: v,
                        entity: 2,
                    });
                }
            }
        }
    }
    mesh.cell_tags = (0..mesh.cells.len() as u64).map(|t| 1000 - 3 * t).collect();
    mesh.facet_tags = (0..mesh.facets.len() as u64).map(|t| 2000 + t).collect();
    // Edges of every fifth cell (some shared, some gone by the time they come), repeats,
    // a degenerate pair, an edge that is no edge and one to a vertex past the end.
    let mut edges: Vec<SplitAt> = Vec::new();
    for c in mesh.cells.iter().step_by(5) {
        let v = &c.vertices;
        for (x, y) in [(0, 1), (1, 3), (0, 2), (2, 3)] {
            edges.push(([v[x], v[y]], None));
        }
    }
    edges.push(([0, 1], Some([0.25, 0.0, 0.1])));
    edges.push(([0, 1], None));
    edges.push(([5, 5], None));
    edges.push(([0, id(3, 3, 3)], None));
    edges.push(([0, 10_000], None));
    (mesh, edges)
}

#[test]
fn splitting_many_edges_in_turn_matches_scanning_every_element() {
    let (mesh, edges) = kuhn_block_and_edges();
    let (fast, count) = mesh.split_edges_at(&edges);
    let slow = split_by_scanning(&mesh, &edges);
    assert!(count > 20, "{count}");
    assert_eq!(fast.vertices.len() - mesh.vertices.len(), count);
    assert_eq!(fast, slow);
}

#[test]
fn keeping_orientation_checks_only_the_cells_a_split_makes() {
    // The Kuhn block of the test above, its bottom-face edges split at points pushed up
    // into the block (kept) or down through the bottom (inverting the cells below: refused),
    // against splitting one edge at a time and checking the whole mesh after each.
    let (mesh, edges) = kuhn_block_and_edges();
    let mut moved: Vec<SplitAt> = Vec::new();
    for (k, &([a, b], _)) in edges.iter().enumerate() {
        let (Some(&pa), Some(&pb)) = (mesh.vertices.get(a as usize), mesh.vertices.get(b as usize))
        else {
            moved.push(([a, b], None));
            continue;
        };
        let mut mid = [0, 1, 2].map(|d| 0.5 * (pa[d] + pb[d]));
        mid[2] += match k % 3 {
            0 => 0.2,
            1 => -0.4,
            _ => 0.0,
        };
        moved.push(([a, b], Some(mid)));
    }
    mesh.check_orientation().unwrap();
    let (fast, count) = mesh.split_edges_keeping_orientation(&moved);
    let mut slow = mesh.clone();
    let mut slow_count = 0;
    for edge in &moved {
        let (next, n) = slow.split_edges_at(std::slice::from_ref(edge));
        if n > 0 && next.check_orientation().is_ok() {
            slow = next;
            slow_count += n;
        }
    }
    assert!(
        count > 10 && count < moved.len() - 10,
        "{count} of {}",
        moved.len()
    );
    assert_eq!(count, slow_count);
    assert_eq!(fast, slow);
    assert!(fast.check_orientation().is_ok());
}
