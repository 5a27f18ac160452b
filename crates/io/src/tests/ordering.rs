use super::*;
use std::path::PathBuf;

// A minimal JSON reader, enough for the ground-truth files (objects, arrays, integers,
// strings without escapes).
#[derive(Debug)]
enum Json {
    Obj(Vec<(String, Json)>),
    Arr(Vec<Json>),
    Int(i64),
    Str(String),
}

impl Json {
    fn get(&self, key: &str) -> &Json {
        match self {
            Json::Obj(items) => {
                &items
                    .iter()
                    .find(|(k, _)| k == key)
                    .unwrap_or_else(|| panic!("no key {key}"))
                    .1
            }
            _ => panic!("not an object"),
        }
    }
    fn entries(&self) -> &[(String, Json)] {
        match self {
            Json::Obj(items) => items,
            _ => panic!("not an object"),
        }
    }
    fn str(&self) -> &str {
        match self {
            Json::Str(s) => s,
            _ => panic!("not a string"),
        }
    }
    fn int(&self) -> i64 {
        match self {
            Json::Int(i) => *i,
            _ => panic!("not an integer"),
        }
    }
    fn triples(&self) -> Vec<[i64; 3]> {
        match self {
            Json::Arr(a) => a
                .iter()
                .map(|t| match t {
                    Json::Arr(c) if c.len() == 3 => [c[0].int(), c[1].int(), c[2].int()],
                    _ => panic!("not a triple"),
                })
                .collect(),
            _ => panic!("not an array"),
        }
    }
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
}

impl Parser<'_> {
    fn ws(&mut self) {
        while self.i < self.s.len() && self.s[self.i].is_ascii_whitespace() {
            self.i += 1;
        }
    }
    fn eat(&mut self, c: u8) {
        self.ws();
        assert_eq!(self.s[self.i], c, "at byte {}", self.i);
        self.i += 1;
    }
    fn peek(&mut self) -> u8 {
        self.ws();
        self.s[self.i]
    }
    fn string(&mut self) -> String {
        self.eat(b'"');
        let start = self.i;
        while self.s[self.i] != b'"' {
            self.i += 1;
        }
        self.i += 1;
        String::from_utf8(self.s[start..self.i - 1].to_vec()).unwrap()
    }
    fn value(&mut self) -> Json {
        match self.peek() {
            b'{' => {
                self.eat(b'{');
                let mut items = Vec::new();
                if self.peek() == b'}' {
                    self.eat(b'}');
                    return Json::Obj(items);
                }
                loop {
                    let k = self.string();
                    self.eat(b':');
                    items.push((k, self.value()));
                    if self.peek() == b',' {
                        self.eat(b',');
                    } else {
                        self.eat(b'}');
                        return Json::Obj(items);
                    }
                }
            }
            b'[' => {
                self.eat(b'[');
                let mut items = Vec::new();
                if self.peek() == b']' {
                    self.eat(b']');
                    return Json::Arr(items);
                }
                loop {
                    items.push(self.value());
                    if self.peek() == b',' {
                        self.eat(b',');
                    } else {
                        self.eat(b']');
                        return Json::Arr(items);
                    }
                }
            }
            b'"' => Json::Str(self.string()),
            _ => {
                let start = self.i;
                while self.i < self.s.len()
                    && (self.s[self.i] == b'-' || self.s[self.i].is_ascii_digit())
                {
                    self.i += 1;
                }
                let text = std::str::from_utf8(&self.s[start..self.i]).unwrap();
                Json::Int(text.parse().unwrap_or_else(|_| panic!("bad number {text}")))
            }
        }
    }
}

fn load(name: &str) -> Json {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests")
        .join("data")
        .join(name);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut parser = Parser {
        s: text.as_bytes(),
        i: 0,
    };
    parser.value()
}

fn shape_named(name: &str) -> Shape {
    Shape::ALL
        .into_iter()
        .find(|s| s.name() == name)
        .unwrap_or_else(|| panic!("unknown shape {name}"))
}

fn compare(file: &str, library: &str, ours: fn(Shape, usize) -> Vec<[i64; 3]>) {
    let json = load(file);
    assert!(json.get("source").str().starts_with(library), "{file}");
    let mut checked = 0;
    for (name, orders) in json.get("lattice").entries() {
        let shape = shape_named(name);
        for (p, truth) in orders.entries() {
            let p: usize = p.parse().unwrap();
            let truth = truth.triples();
            let mine = ours(shape, p);
            assert_eq!(mine.len(), truth.len(), "{file}: {shape:?} p={p}");
            for (k, (m, t)) in mine.iter().zip(&truth).enumerate() {
                assert_eq!(m, t, "{file}: {shape:?} p={p}: node {k}");
            }
            checked += 1;
        }
    }
    assert!(checked >= 6 * 8, "{file}: only {checked} cases");
}

#[test]
fn gmsh_orderings_match_gmsh() {
    compare("orderings_gmsh.json", "gmsh ", gmsh_lattice);
}

#[test]
fn vtk_orderings_match_vtk() {
    compare("orderings_vtk.json", "vtk ", vtk_lattice);
}

#[test]
fn gmsh_type_numbers_match_gmsh() {
    let json = load("orderings_gmsh.json");
    for (name, types) in json.get("types").entries() {
        let shape = shape_named(name);
        for (p, t) in types.entries() {
            let p: usize = p.parse().unwrap();
            let t = t.int() as i32;
            assert_eq!(gmsh_element_type(shape, p), Some(t), "{shape:?} p={p}");
            assert_eq!(gmsh_type_shape(t), Some((shape, p)));
        }
        let max = gmsh_max_order(shape);
        assert_eq!(types.entries().len(), max, "{shape:?}");
        assert_eq!(gmsh_element_type(shape, max + 1), None);
        assert_eq!(gmsh_element_type(shape, 0), None);
    }
    assert_eq!(gmsh_type_shape(7), None); // pyramid
    assert_eq!(gmsh_type_shape(15), None); // point
}

#[test]
fn permutations_are_bijections_for_all_orders() {
    for shape in Shape::ALL {
        for p in 1..=NodeFamily::Equispaced.max_order() {
            for (name, perm) in [
                ("gmsh", gmsh_permutation(shape, p)),
                ("vtk", vtk_permutation(shape, p)),
            ] {
                let inv = invert_permutation(&perm);
                assert!(
                    inv.iter().all(|&k| k != usize::MAX),
                    "{name} {shape:?} p={p}"
                );
                for (k, &i) in perm.iter().enumerate() {
                    assert_eq!(inv[i], k);
                }
                // Vertices first, in the shared linear numbering.
                let vertices: Vec<usize> = (0..shape.num_vertices()).collect();
                assert_eq!(perm[..vertices.len()], vertices, "{name} {shape:?} p={p}");
            }
        }
    }
}

#[test]
fn permutation_maps_lattice_to_lattice() {
    for shape in Shape::ALL {
        for p in 1..=7 {
            let reference = ReferenceNodes::new(shape, p, NodeFamily::Equispaced);
            let lattice = gmsh_lattice(shape, p);
            for (k, &i) in gmsh_permutation(shape, p).iter().enumerate() {
                assert_eq!(reference.lattice()[i], lattice[k]);
            }
            let lattice = vtk_lattice(shape, p);
            for (k, &i) in vtk_permutation(shape, p).iter().enumerate() {
                assert_eq!(reference.lattice()[i], lattice[k]);
            }
        }
    }
}

#[test]
fn linear_orders_are_the_identity() {
    for shape in Shape::ALL {
        let id: Vec<usize> = (0..shape.num_vertices()).collect();
        assert_eq!(gmsh_permutation(shape, 1), id);
        assert_eq!(vtk_permutation(shape, 1), id);
    }
}
