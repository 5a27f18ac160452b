use super::*;

/// A rational biquadratic-by-cubic patch with uneven weights and an interior knot in u.
fn patch() -> NurbsSurface {
    let (n_u, n_v) = (4, 4);
    let mut cps = Vec::new();
    let mut weights = Vec::new();
    for i in 0..n_u {
        for j in 0..n_v {
            let (x, y) = (i as f64, j as f64);
            cps.push([x, y, (x * 1.3 + y * 0.7).sin() + 0.2 * x * y]);
            weights.push(1.0 + 0.3 * ((i * 7 + j * 3) % 5) as f64);
        }
    }
    NurbsSurface::new(
        2,
        3,
        vec![0.0, 0.0, 0.0, 0.4, 1.0, 1.0, 1.0],
        vec![0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0, 1.0],
        cps,
        weights,
    )
    .unwrap()
}

#[test]
fn bilinear_patch_matches_closed_form() {
    // S(u,v) = (u, v, u v) from the corners (0,0,0), (0,1,0), (1,0,0), (1,1,1).
    let s = NurbsSurface::new(
        1,
        1,
        vec![0.0, 0.0, 1.0, 1.0],
        vec![0.0, 0.0, 1.0, 1.0],
        vec![
            [0.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 1.0],
        ],
        vec![1.0; 4],
    )
    .unwrap();
    for &(u, v) in &[(0.0, 0.0), (0.3, 0.8), (1.0, 0.5), (1.0, 1.0)] {
        let d = s.derivatives(u, v);
        let exact = [u, v, u * v];
        for k in 0..3 {
            assert!((d.point[k] - exact[k]).abs() < 1e-15);
            assert!((s.point(u, v)[k] - exact[k]).abs() < 1e-15);
        }
        assert!(vec3::distance(d.du, [1.0, 0.0, v]) < 1e-15);
        assert!(vec3::distance(d.dv, [0.0, 1.0, u]) < 1e-15);
        assert!(vec3::distance(d.duv, [0.0, 0.0, 1.0]) < 1e-15);
        assert!(vec3::norm(d.duu) < 1e-15 && vec3::norm(d.dvv) < 1e-15);
    }
}

#[test]
fn partial_derivatives_match_finite_differences() {
    let s = patch();
    let h = 1e-5;
    for i in 1..20 {
        for j in 1..20 {
            let (u, v) = (i as f64 / 20.0, j as f64 / 20.0);
            if (u - 0.4).abs() < 2.0 * h {
                continue;
            }
            let d = s.derivatives(u, v);
            let (um, up) = (s.derivatives(u - h, v), s.derivatives(u + h, v));
            let (vm, vp) = (s.derivatives(u, v - h), s.derivatives(u, v + h));
            for k in 0..3 {
                let checks = [
                    (d.du[k], (up.point[k] - um.point[k]) / (2.0 * h)),
                    (d.dv[k], (vp.point[k] - vm.point[k]) / (2.0 * h)),
                    (d.duu[k], (up.du[k] - um.du[k]) / (2.0 * h)),
                    (d.duv[k], (vp.du[k] - vm.du[k]) / (2.0 * h)),
                    (d.duv[k], (up.dv[k] - um.dv[k]) / (2.0 * h)),
                    (d.dvv[k], (vp.dv[k] - vm.dv[k]) / (2.0 * h)),
                ];
                for (exact, fd) in checks {
                    assert!((exact - fd).abs() < 1e-7 * (1.0 + exact.abs()), "{u} {v}");
                }
            }
        }
    }
}

#[test]
fn net_size_is_checked() {
    let mut s = patch();
    s.control_points.pop();
    assert!(matches!(
        s.validate(),
        Err(NurbsError::ControlNetSize {
            n_u: 4,
            n_v: 4,
            found: 15
        })
    ));
    let s = patch();
    assert_eq!(s.domain(), ((0.0, 1.0), (0.0, 1.0)));
    assert!(!s.is_closed_u() && !s.is_closed_v());
    assert_eq!(s.degenerate_edges(), [false; 4]);
}

/// A flat rational patch (the curved patch's net flattened onto a tilted plane, weights
/// kept) is in its plane: the normal found is the plane's to 1e-15 and every control point
/// is on it; raising one control point by 1e-9 of the size, or a sphere, is not planar.
#[test]
fn a_flat_patch_has_its_plane_and_a_bent_one_none() {
    let normal = {
        let n = [0.3, -0.4, 1.2];
        let l: f64 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
        [n[0] / l.sqrt(), n[1] / l.sqrt(), n[2] / l.sqrt()]
    };
    let mut flat = patch();
    for p in &mut flat.control_points {
        // Onto the plane through (1, 2, 3) with that normal.
        let off = (p[0] - 1.0) * normal[0] + (p[1] - 2.0) * normal[1] + (p[2] - 3.0) * normal[2];
        for d in 0..3 {
            p[d] -= off * normal[d];
        }
    }
    let (point, found) = flat.plane().expect("a flat patch has a plane");
    let along = found[0] * normal[0] + found[1] * normal[1] + found[2] * normal[2];
    assert!((along.abs() - 1.0).abs() < 1e-15, "{found:?}");
    let off =
        (point[0] - 1.0) * normal[0] + (point[1] - 2.0) * normal[1] + (point[2] - 3.0) * normal[2];
    assert!(off.abs() < 1e-13, "{off:e}");
    let mut bumped = flat.clone();
    let size = bumped.size();
    let p = &mut bumped.control_points[5];
    for d in 0..3 {
        p[d] += 1e-9 * size * normal[d];
    }
    assert!(bumped.plane().is_none());
    assert!(patch().plane().is_none());
    assert!(crate::shapes::sphere([0.0; 3], 1.0)
        .unwrap()
        .plane()
        .is_none());
}
