use super::*;

#[test]
fn canonical_quad_face_is_independent_of_rotation_and_direction() {
    let cycle = [7u32, 3, 9, 5];
    let expect = canonical_face(&cycle);
    assert_eq!(expect, vec![3, 7, 5, 9]);
    for start in 0..4 {
        let rotated: Vec<u32> = (0..4).map(|k| cycle[(start + k) % 4]).collect();
        let reversed: Vec<u32> = (0..4).map(|k| cycle[(start + 4 - k) % 4]).collect();
        assert_eq!(canonical_face(&rotated), expect);
        assert_eq!(canonical_face(&reversed), expect);
    }
    assert_eq!(canonical_face(&[9, 2, 4]), vec![2, 4, 9]);
}
