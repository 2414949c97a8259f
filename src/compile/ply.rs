//! Stanford PLY meshes (Turk 1994, "The PLY polygon file format"): ASCII and binary of either
//! byte order, read by a small reader of our own into the same [`ObjMesh`] an OBJ file gives.
//!
//! Why not a crate: `ply-rs` is unmaintained since 2020 and its maintained fork `ply-rs-bw`
//! keeps its design, one ordered map of properties per element instance (a million vertices are
//! a million maps), and its errors name neither the element nor the property. The format's
//! header-then-records structure fits in this file, and reading the few properties a renderer
//! uses straight into arrays keeps a 1M-triangle binary PLY as fast to load as its OBJ.
//!
//! Read: the `vertex` element's `x y z`, `nx ny nz`, texture coordinates (`u v`, `s t`,
//! `texture_u texture_v` or `texture_s texture_t`) and the `face` element's `vertex_indices`
//! (or `vertex_index`) list. Vertex colours (`red green blue`) are noticed and reported as
//! ignored: caustic's meshes carry no per-vertex colour. Every other element and property is
//! read past.

use std::path::Path;

use glam::{Vec2, Vec3};

use super::mesh_data::{Corner, FaceNames, ObjMesh, push_polygon};
pub use super::mesh_file::PlyError;

/// How the records after the header are stored.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Encoding {
    Ascii,
    Little,
    Big,
}

/// A scalar type of the format.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(word: &str) -> Option<Scalar> {
        Some(match word {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn is_integer(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

/// A property of an element: a scalar, or a list with a count type and an item type.
#[derive(Debug, Clone)]
struct Property {
    name: String,
    scalar: Scalar,
    list_count: Option<Scalar>,
}

#[derive(Debug, Clone)]
struct Element {
    name: String,
    count: usize,
    properties: Vec<Property>,
}

/// The header: encoding, elements in file order, and where the records start.
struct Header {
    encoding: Encoding,
    elements: Vec<Element>,
    body: usize,
    /// 1-based line of the first record (ASCII).
    body_line: usize,
}

/// The most elements a header may declare, of any kind: far more than any mesh needs, and a
/// bound on what a hostile count can make the reader reserve before reading any record.
const MAX_COUNT: usize = 1 << 30;

/// Parses PLY bytes (`path` only names the file in messages).
///
/// # Errors
/// A [`PlyError`] naming the file and the header line, element or property at fault.
pub fn parse_ply(bytes: &[u8], path: &Path) -> Result<ObjMesh, PlyError> {
    let fail = |problem: String| PlyError {
        path: path.to_path_buf(),
        problem,
    };
    let header = parse_header(bytes).map_err(fail)?;
    let mut mesh = ObjMesh::default();
    let mut reader = Reader {
        bytes,
        pos: header.body,
        line: header.body_line,
        encoding: header.encoding,
    };
    let mut faces: Vec<(usize, Vec<u32>)> = Vec::new();
    let mut have_vertices = false;
    for element in &header.elements {
        match element.name.as_str() {
            "vertex" => {
                read_vertices(&mut reader, element, &mut mesh).map_err(fail)?;
                have_vertices = true;
            }
            "face" => read_faces(&mut reader, element, &mut faces).map_err(fail)?,
            _ => skip_element(&mut reader, element).map_err(fail)?,
        }
    }
    if !have_vertices {
        return Err(fail(
            "the header declares no `vertex` element; a PLY mesh needs `element vertex N` with properties `x`, `y`, `z`".into(),
        ));
    }
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(fail(format!(
            "vertex {i} (0-based, as PLY faces count) has a non-finite coordinate"
        )));
    }
    let vertices = mesh.positions.len();
    let (has_n, has_t) = (!mesh.normals.is_empty(), !mesh.uvs.is_empty());
    for (face, indices) in faces {
        if let Some(&bad) = indices.iter().find(|&&i| i as usize >= vertices) {
            return Err(fail(format!(
                "element `face` {face}: property `vertex_indices` uses vertex {bad}, but the file has {vertices} vertices (indices start at 0)"
            )));
        }
        let corners: Vec<Corner> = indices
            .iter()
            .map(|&i| Corner {
                p: i,
                n: has_n.then_some(i),
                t: has_t.then_some(i),
            })
            .collect();
        let shape: Vec<Vec3> = indices
            .iter()
            .map(|&i| mesh.positions[i as usize])
            .collect();
        push_polygon(
            &mut mesh,
            &corners,
            &shape,
            FaceNames::default(),
            &format!("face {face}"),
        );
    }
    if mesh.triangles.is_empty() {
        return Err(fail(
            "no faces: the file has no `face` element with `vertex_indices` of three or more corners (a point cloud?)".into(),
        ));
    }
    Ok(mesh)
}

/// Reads the header up to `end_header`.
fn parse_header(bytes: &[u8]) -> Result<Header, String> {
    let mut pos = 0;
    let mut line_no = 0;
    let mut encoding = None;
    let mut elements: Vec<Element> = Vec::new();
    loop {
        let Some(len) = bytes[pos..].iter().position(|b| *b == b'\n') else {
            return Err("the header has no `end_header` line".into());
        };
        let raw = &bytes[pos..pos + len];
        pos += len + 1;
        line_no += 1;
        let line = std::str::from_utf8(raw)
            .map_err(|_| format!("header line {line_no} is not text"))?
            .trim();
        let words: Vec<&str> = line.split_whitespace().collect();
        let at = |what: &str| format!("header line {line_no} `{line}`: {what}");
        match words.as_slice() {
            ["ply"] if line_no == 1 => {}
            _ if line_no == 1 => return Err(at("the first line must be `ply`")),
            ["format", kind, version] => {
                if !version.starts_with('1') {
                    return Err(at("only PLY format version 1.0 is known"));
                }
                encoding = Some(match *kind {
                    "ascii" => Encoding::Ascii,
                    "binary_little_endian" => Encoding::Little,
                    "binary_big_endian" => Encoding::Big,
                    _ => {
                        return Err(at(
                            "the format must be `ascii`, `binary_little_endian` or `binary_big_endian`",
                        ));
                    }
                });
            }
            ["comment", ..] | ["obj_info", ..] | [] => {}
            ["element", name, count] => {
                let count: usize = count
                    .parse()
                    .map_err(|_| at("the element count must be a whole number"))?;
                if count > MAX_COUNT {
                    return Err(at(&format!(
                        "{count} elements is more than the {MAX_COUNT} caustic reads"
                    )));
                }
                elements.push(Element {
                    name: (*name).to_string(),
                    count,
                    properties: Vec::new(),
                });
            }
            ["property", "list", count, item, name] => {
                let (Some(count), Some(item)) = (Scalar::parse(count), Scalar::parse(item)) else {
                    return Err(at(TYPES));
                };
                if !count.is_integer() {
                    return Err(at("a list's count type must be an integer type"));
                }
                let Some(e) = elements.last_mut() else {
                    return Err(at("a property before any `element`"));
                };
                e.properties.push(Property {
                    name: (*name).to_string(),
                    scalar: item,
                    list_count: Some(count),
                });
            }
            ["property", ty, name] => {
                let Some(scalar) = Scalar::parse(ty) else {
                    return Err(at(TYPES));
                };
                let Some(e) = elements.last_mut() else {
                    return Err(at("a property before any `element`"));
                };
                e.properties.push(Property {
                    name: (*name).to_string(),
                    scalar,
                    list_count: None,
                });
            }
            ["end_header"] => break,
            _ => {
                return Err(at(
                    "not a header statement (`format`, `element`, `property`, `comment`, `obj_info` or `end_header`)",
                ));
            }
        }
    }
    let Some(encoding) = encoding else {
        return Err("the header has no `format` line".into());
    };
    Ok(Header {
        encoding,
        elements,
        body: pos,
        body_line: line_no + 1,
    })
}

const TYPES: &str =
    "property types are char, uchar, short, ushort, int, uint, float, double (or int8 … float64)";

/// The record reader: a position in the bytes, and the line for ASCII.
struct Reader<'a> {
    bytes: &'a [u8],
    pos: usize,
    line: usize,
    encoding: Encoding,
}

impl Reader<'_> {
    /// The next value of type `s`, as f64 (exact for every PLY type).
    fn value(&mut self, s: Scalar) -> Result<f64, &'static str> {
        if self.encoding == Encoding::Ascii {
            return self.word(s);
        }
        let n = s.size();
        let Some(b) = self.bytes.get(self.pos..self.pos + n) else {
            return Err("the file ends before it");
        };
        self.pos += n;
        let mut a = [0u8; 8];
        a[..n].copy_from_slice(b);
        if self.encoding == Encoding::Big {
            a[..n].reverse();
        }
        Ok(match s {
            Scalar::I8 => f64::from(a[0] as i8),
            Scalar::U8 => f64::from(a[0]),
            Scalar::I16 => f64::from(i16::from_le_bytes([a[0], a[1]])),
            Scalar::U16 => f64::from(u16::from_le_bytes([a[0], a[1]])),
            Scalar::I32 => f64::from(i32::from_le_bytes([a[0], a[1], a[2], a[3]])),
            Scalar::U32 => f64::from(u32::from_le_bytes([a[0], a[1], a[2], a[3]])),
            Scalar::F32 => f64::from(f32::from_le_bytes([a[0], a[1], a[2], a[3]])),
            Scalar::F64 => f64::from_le_bytes(a),
        })
    }

    /// The next whitespace-separated word of an ASCII body, parsed as type `s`.
    fn word(&mut self, s: Scalar) -> Result<f64, &'static str> {
        while let Some(&b) = self.bytes.get(self.pos) {
            if !b.is_ascii_whitespace() {
                break;
            }
            if b == b'\n' {
                self.line += 1;
            }
            self.pos += 1;
        }
        let start = self.pos;
        while self
            .bytes
            .get(self.pos)
            .is_some_and(|b| !b.is_ascii_whitespace())
        {
            self.pos += 1;
        }
        if start == self.pos {
            return Err("the file ends before it");
        }
        let text = std::str::from_utf8(&self.bytes[start..self.pos]).map_err(|_| "not text")?;
        if s.is_integer() {
            text.parse::<i64>()
                .map(|v| v as f64)
                .map_err(|_| "not a whole number")
        } else {
            text.parse::<f64>().map_err(|_| "not a number")
        }
    }

    /// Where the reader is, for messages: the ASCII line or the byte offset.
    fn place(&self) -> String {
        match self.encoding {
            Encoding::Ascii => format!("line {}", self.line),
            Encoding::Little | Encoding::Big => format!("byte {}", self.pos),
        }
    }

    /// One property's values (one for a scalar, the items for a list) into `out`.
    fn property(
        &mut self,
        e: &Element,
        index: usize,
        p: &Property,
        out: &mut Vec<f64>,
    ) -> Result<(), String> {
        out.clear();
        let err = |r: &Self, what: &str| {
            format!(
                "element `{}` {index}, property `{}` ({}): {what}",
                e.name,
                p.name,
                r.place()
            )
        };
        match p.list_count {
            None => out.push(self.value(p.scalar).map_err(|w| err(self, w))?),
            Some(count) => {
                let n = self.value(count).map_err(|w| err(self, w))?;
                if !(0.0..=f64::from(u16::MAX)).contains(&n) {
                    return Err(err(
                        self,
                        &format!("a list of {n} items (0 to 65535 are read)"),
                    ));
                }
                for _ in 0..n as usize {
                    out.push(self.value(p.scalar).map_err(|w| err(self, w))?);
                }
            }
        }
        Ok(())
    }
}

/// Which vertex property feeds which attribute slot.
#[derive(Clone, Copy)]
enum Slot {
    Pos(usize),
    Normal(usize),
    Uv(usize),
    Colour,
    Other,
}

fn slot(name: &str) -> Slot {
    match name {
        "x" => Slot::Pos(0),
        "y" => Slot::Pos(1),
        "z" => Slot::Pos(2),
        "nx" => Slot::Normal(0),
        "ny" => Slot::Normal(1),
        "nz" => Slot::Normal(2),
        "u" | "s" | "texture_u" | "texture_s" => Slot::Uv(0),
        "v" | "t" | "texture_v" | "texture_t" => Slot::Uv(1),
        "red" | "green" | "blue" | "r" | "g" | "b" | "diffuse_red" | "diffuse_green"
        | "diffuse_blue" => Slot::Colour,
        _ => Slot::Other,
    }
}

fn read_vertices(r: &mut Reader, e: &Element, mesh: &mut ObjMesh) -> Result<(), String> {
    let slots: Vec<Slot> = e.properties.iter().map(|p| slot(&p.name)).collect();
    let has = |f: &dyn Fn(&Slot) -> bool| slots.iter().filter(|s| f(s)).count();
    if has(&|s| matches!(s, Slot::Pos(_))) < 3 {
        return Err(
            "element `vertex` needs the properties `x`, `y` and `z`; found: ".to_string()
                + &e.properties
                    .iter()
                    .map(|p| format!("`{}`", p.name))
                    .collect::<Vec<_>>()
                    .join(", "),
        );
    }
    let normals = has(&|s| matches!(s, Slot::Normal(_))) == 3;
    let uvs = has(&|s| matches!(s, Slot::Uv(_))) == 2;
    let colours = has(&|s| matches!(s, Slot::Colour)) > 0;
    mesh.positions.reserve(e.count);
    if normals {
        mesh.normals.reserve(e.count);
    }
    if uvs {
        mesh.uvs.reserve(e.count);
    }
    let mut values = Vec::new();
    for i in 0..e.count {
        let (mut p, mut n, mut t) = ([0f32; 3], [0f32; 3], [0f32; 2]);
        for (prop, s) in e.properties.iter().zip(&slots) {
            r.property(e, i, prop, &mut values)?;
            let v = values.first().copied().unwrap_or(0.0) as f32;
            match *s {
                Slot::Pos(k) => p[k] = v,
                Slot::Normal(k) => n[k] = v,
                Slot::Uv(k) => t[k] = v,
                Slot::Colour | Slot::Other => {}
            }
        }
        mesh.positions.push(Vec3::from(p));
        if normals {
            mesh.normals.push(Vec3::from(n));
        }
        if uvs {
            // PLY's v grows upwards, as OBJ's: the renderer's grows downwards.
            mesh.uvs.push(Vec2::new(t[0], 1.0 - t[1]));
        }
    }
    if colours {
        mesh.warnings.push(
            "has vertex colours, which caustic's meshes do not carry: they are ignored (the node's material gives the colour)".into(),
        );
    }
    Ok(())
}

fn read_faces(
    r: &mut Reader,
    e: &Element,
    faces: &mut Vec<(usize, Vec<u32>)>,
) -> Result<(), String> {
    let Some(k) = e.properties.iter().position(|p| {
        p.list_count.is_some() && matches!(p.name.as_str(), "vertex_indices" | "vertex_index")
    }) else {
        return Err(
            "element `face` has no list property `vertex_indices` (or `vertex_index`)".into(),
        );
    };
    if !e.properties[k].scalar.is_integer() {
        return Err(format!(
            "element `face`, property `{}`: vertex indices must have an integer type",
            e.properties[k].name
        ));
    }
    faces.reserve(e.count);
    let mut values = Vec::new();
    for i in 0..e.count {
        for (j, prop) in e.properties.iter().enumerate() {
            r.property(e, i, prop, &mut values)?;
            if j != k {
                continue;
            }
            if values.len() < 3 {
                return Err(format!(
                    "element `face` {i}, property `{}`: a face needs at least three corners, found {}",
                    prop.name,
                    values.len()
                ));
            }
            if let Some(v) = values
                .iter()
                .find(|v| **v < 0.0 || **v > f64::from(u32::MAX))
            {
                return Err(format!(
                    "element `face` {i}, property `{}`: vertex index {v} (indices start at 0)",
                    prop.name
                ));
            }
            faces.push((i, values.iter().map(|v| *v as u32).collect()));
        }
    }
    Ok(())
}

fn skip_element(r: &mut Reader, e: &Element) -> Result<(), String> {
    let mut values = Vec::new();
    for i in 0..e.count {
        for p in &e.properties {
            r.property(e, i, p, &mut values)?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A unit square as a quad and a triangle, with normals and uvs, in each encoding.
    fn square(encoding: &str) -> Vec<u8> {
        let mut out = format!(
            "ply\nformat {encoding} 1.0\ncomment made by hand\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nproperty float s\nproperty float t\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n"
        )
        .into_bytes();
        let v: [[f32; 8]; 4] = [
            [0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0],
            [1.0, 0.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0],
            [1.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0],
            [0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 1.0],
        ];
        let face = [0i32, 1, 2, 3];
        match encoding {
            "ascii" => {
                for row in v {
                    let words: Vec<String> = row.iter().map(f32::to_string).collect();
                    out.extend(words.join(" ").bytes());
                    out.push(b'\n');
                }
                out.extend(b"4 0 1 2 3\n");
            }
            _ => {
                let big = encoding == "binary_big_endian";
                for x in v.iter().flatten() {
                    out.extend(if big {
                        x.to_be_bytes()
                    } else {
                        x.to_le_bytes()
                    });
                }
                out.push(4);
                for i in face {
                    out.extend(if big {
                        i.to_be_bytes()
                    } else {
                        i.to_le_bytes()
                    });
                }
            }
        }
        out
    }

    #[test]
    fn the_three_encodings_give_the_same_square() {
        for enc in ["ascii", "binary_little_endian", "binary_big_endian"] {
            let m = parse_ply(&square(enc), Path::new("sq.ply"))
                .unwrap_or_else(|e| panic!("{enc}: {e}"));
            assert_eq!(m.positions[2], Vec3::new(1.0, 1.0, 0.0), "{enc}");
            assert_eq!(m.normals[3], Vec3::Z, "{enc}");
            // (s, t) = (1, 1) is the image's top-right: v = 1 − t = 0.
            assert_eq!(m.uvs[2], Vec2::new(1.0, 0.0), "{enc}");
            assert_eq!(m.triangles.len(), 2, "{enc}");
            let area: f32 = m
                .triangles
                .iter()
                .map(|t| {
                    let p = t.map(|c| m.positions[c.p as usize]);
                    (p[1] - p[0]).cross(p[2] - p[0]).length() / 2.0
                })
                .sum();
            assert!((area - 1.0).abs() < 1e-6, "{enc}: {area}");
            assert!(m.warnings.is_empty(), "{enc}: {:?}", m.warnings);
        }
    }

    #[test]
    fn errors_name_the_element_and_property() {
        let mut bytes = square("binary_little_endian");
        bytes.truncate(bytes.len() - 3);
        let e = parse_ply(&bytes, Path::new("cut.ply")).expect_err("truncated");
        assert!(
            e.to_string()
                .starts_with("`cut.ply` (PLY): element `face` 0, property `vertex_indices` (byte"),
            "{e}"
        );
        assert!(e.to_string().ends_with("the file ends before it"), "{e}");
        let text = String::from_utf8(square("ascii"))
            .expect("ascii")
            .replace("4 0 1 2 3", "3 0 1 9");
        let e = parse_ply(text.as_bytes(), Path::new("far.ply")).expect_err("index");
        assert!(
            e.to_string().contains("element `face` 0: property `vertex_indices` uses vertex 9, but the file has 4 vertices"),
            "{e}"
        );
        let text = String::from_utf8(square("ascii"))
            .expect("ascii")
            .replace("property float t", "property flot t");
        let e = parse_ply(text.as_bytes(), Path::new("ty.ply")).expect_err("type");
        assert!(
            e.to_string()
                .contains("header line 12 `property flot t`: property types are"),
            "{e}"
        );
        let text = String::from_utf8(square("ascii"))
            .expect("ascii")
            .replace("0 1 0 0 0 1 0 1", "0 1 zero 0 0 1 0 1");
        let e = parse_ply(text.as_bytes(), Path::new("nan.ply")).expect_err("number");
        assert!(
            e.to_string()
                .contains("element `vertex` 3, property `z` (line 19): not a number"),
            "{e}"
        );
    }
}
