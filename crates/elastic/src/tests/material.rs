use super::*;

#[test]
fn lame_parameters_of_the_paper_material() {
    // E = 10, ν = 0.4: λ = 4 / (1.4 · 0.2) = 100/7, μ = 10 / 2.8 = 25/7.
    let (lambda, mu) = Material::default().lame();
    assert!((lambda - 100.0 / 7.0).abs() < 1e-13);
    assert!((mu - 25.0 / 7.0).abs() < 1e-13);
    // ν = 0: no lateral coupling, μ = E/2.
    let (lambda, mu) = Material::new(2.0, 0.0).unwrap().lame();
    assert_eq!((lambda, mu), (0.0, 1.0));
}

#[test]
fn unphysical_materials_are_rejected() {
    for (e, nu) in [
        (10.0, 0.5),
        (10.0, -1.0),
        (0.0, 0.3),
        (-1.0, 0.3),
        (f64::NAN, 0.3),
        (10.0, f64::NAN),
        (f64::INFINITY, 0.3),
    ] {
        assert!(
            matches!(
                Material::new(e, nu),
                Err(ElasticError::InvalidMaterial { .. })
            ),
            "E = {e}, ν = {nu}"
        );
    }
    assert!(Material::new(1.0, 0.499).is_ok());
    assert!(Material::new(1.0, -0.99).is_ok());
}
