//! Typed parameter lists (`"float fov" [45]`) and the accessors statements read them with.
//! Every accessor marks the parameter used, so the builder can warn about the ones no statement
//! understood; wrong types, counts and out-of-range numbers are errors naming the parameter.

use std::cell::Cell;

use glam::Vec3;

use super::error::ParseError;
use crate::diag::SourcePos as Pos;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ParamType {
    Float,
    Integer,
    Bool,
    Point,
    Vector,
    Normal,
    String,
    Texture,
    Color,
}

impl ParamType {
    pub fn from_name(name: &str) -> Option<Self> {
        Some(match name {
            "float" => Self::Float,
            "integer" => Self::Integer,
            "bool" => Self::Bool,
            "point" | "point3" => Self::Point,
            "vector" | "vector3" => Self::Vector,
            "normal" | "normal3" => Self::Normal,
            "string" => Self::String,
            "texture" => Self::Texture,
            "color" | "rgb" => Self::Color,
            _ => return None,
        })
    }

    pub fn name(self) -> &'static str {
        match self {
            Self::Float => "float",
            Self::Integer => "integer",
            Self::Bool => "bool",
            Self::Point => "point",
            Self::Vector => "vector",
            Self::Normal => "normal",
            Self::String => "string",
            Self::Texture => "texture",
            Self::Color => "color",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Values {
    Numbers(Vec<f64>),
    Strings(Vec<String>),
}

impl Values {
    fn len(&self) -> usize {
        match self {
            Values::Numbers(v) => v.len(),
            Values::Strings(v) => v.len(),
        }
    }
}

#[derive(Debug)]
pub struct Param {
    pub ty: ParamType,
    pub name: String,
    pub values: Values,
    pub pos: Pos,
    used: Cell<bool>,
}

impl Param {
    pub fn new(ty: ParamType, name: String, values: Values, pos: Pos) -> Self {
        Self {
            ty,
            name,
            values,
            pos,
            used: Cell::new(false),
        }
    }

    /// The declaration as written, e.g. `float fov`.
    pub fn decl(&self) -> String {
        format!("{} {}", self.ty.name(), self.name)
    }

    pub fn is_used(&self) -> bool {
        self.used.get()
    }
}

/// A texture-or-constant parameter before the texture name is resolved.
#[derive(Clone, Debug, PartialEq)]
pub enum ConstOrTextureName {
    Const(Vec3),
    Named { name: String, pos: Pos },
}

/// The parameters of one statement, with the statement's label (e.g. `Shape "mesh"`) for
/// messages.
#[derive(Debug)]
pub struct ParamList {
    pub statement: String,
    pub params: Vec<Param>,
}

impl ParamList {
    pub fn new(statement: String, params: Vec<Param>) -> Self {
        Self { statement, params }
    }

    /// The parameter named `name`, marked used. A later duplicate wins, as in LuxRender.
    pub fn find(&self, name: &str) -> Option<&Param> {
        let p = self.params.iter().rev().find(|p| p.name == name)?;
        p.used.set(true);
        Some(p)
    }

    /// The last parameter named `name` whose type passes `ty`, marked used.
    fn find_typed(&self, name: &str, ty: impl Fn(ParamType) -> bool) -> Option<&Param> {
        let p = self
            .params
            .iter()
            .rev()
            .find(|p| p.name == name && ty(p.ty))?;
        p.used.set(true);
        Some(p)
    }

    /// [`Self::float`] among the float and integer parameters only. LuxRender looks a
    /// parameter up by type and name, so marble's "float scale" and its 3D mapping's "vector
    /// scale" are two parameters.
    pub fn float_typed(&self, name: &str, default: f32) -> Result<f32, ParseError> {
        let Some(p) = self.find_typed(name, |t| matches!(t, ParamType::Float | ParamType::Integer))
        else {
            return Ok(default);
        };
        let v = self.exactly(p, 1, "one float")?;
        self.to_f32(p, 0, v[0])
    }

    /// [`Self::vec3`] among the point, vector and normal parameters only (see
    /// [`Self::float_typed`]).
    pub fn vec3_typed(&self, name: &str, default: Vec3) -> Result<Vec3, ParseError> {
        let Some(p) = self.find_typed(name, |t| {
            matches!(t, ParamType::Point | ParamType::Vector | ParamType::Normal)
        }) else {
            return Ok(default);
        };
        let v = self.exactly(p, 3, "one 3-component value")?;
        Ok(Vec3::new(
            self.to_f32(p, 0, v[0])?,
            self.to_f32(p, 1, v[1])?,
            self.to_f32(p, 2, v[2])?,
        ))
    }

    /// Marks a parameter as knowingly ignored.
    pub fn ignore(&self, name: &str) {
        for p in self.params.iter().filter(|p| p.name == name) {
            p.used.set(true);
        }
    }

    /// Marks every parameter as knowingly ignored (a statement left whole).
    pub fn ignore_all(&self) {
        for p in &self.params {
            p.used.set(true);
        }
    }

    pub fn error(&self, p: &Param, message: impl Into<String>) -> ParseError {
        ParseError::Parameter {
            pos: p.pos.clone(),
            statement: self.statement.clone(),
            param: p.decl(),
            message: message.into(),
        }
    }

    fn type_error(&self, p: &Param, expected: &str) -> ParseError {
        self.error(p, format!("expected {expected}"))
    }

    fn numbers<'p>(&self, p: &'p Param, expected: &str) -> Result<&'p [f64], ParseError> {
        match &p.values {
            Values::Numbers(v) => Ok(v),
            Values::Strings(_) => Err(self.type_error(p, expected)),
        }
    }

    fn exactly<'p>(&self, p: &'p Param, n: usize, expected: &str) -> Result<&'p [f64], ParseError> {
        let v = self.numbers(p, expected)?;
        if v.len() != n {
            return Err(self.error(p, format!("expected {expected}, got {} values", v.len())));
        }
        Ok(v)
    }

    fn to_f32(&self, p: &Param, index: usize, v: f64) -> Result<f32, ParseError> {
        let f = v as f32;
        if f.is_finite() {
            Ok(f)
        } else {
            Err(self.error(
                p,
                format!(
                    "value {} ({v}) is out of range for a 32-bit float",
                    index + 1
                ),
            ))
        }
    }

    pub fn float(&self, name: &str, default: f32) -> Result<f32, ParseError> {
        let Some(p) = self.find(name) else {
            return Ok(default);
        };
        if !matches!(p.ty, ParamType::Float | ParamType::Integer) {
            return Err(self.type_error(p, "one float"));
        }
        let v = self.exactly(p, 1, "one float")?;
        self.to_f32(p, 0, v[0])
    }

    /// A float array, each value checked to fit an `f32`.
    pub fn floats(&self, name: &str) -> Result<Option<(Vec<f32>, &Param)>, ParseError> {
        let Some(p) = self.find(name) else {
            return Ok(None);
        };
        if !matches!(p.ty, ParamType::Float | ParamType::Integer) {
            return Err(self.type_error(p, "floats"));
        }
        let v = self.numbers(p, "floats")?;
        let out = v
            .iter()
            .enumerate()
            .map(|(i, &x)| self.to_f32(p, i, x))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Some((out, p)))
    }

    fn integer_value(&self, p: &Param, index: usize, v: f64) -> Result<i64, ParseError> {
        if v.fract() != 0.0 || !v.is_finite() || v.abs() > i32::MAX as f64 {
            return Err(self.error(
                p,
                format!(
                    "value {} ({v}) is not an integer in the 32-bit range",
                    index + 1
                ),
            ));
        }
        Ok(v as i64)
    }

    pub fn int(&self, name: &str, default: i32) -> Result<i32, ParseError> {
        let Some(p) = self.find(name) else {
            return Ok(default);
        };
        if !matches!(p.ty, ParamType::Integer | ParamType::Float) {
            return Err(self.type_error(p, "one integer"));
        }
        let v = self.exactly(p, 1, "one integer")?;
        Ok(self.integer_value(p, 0, v[0])? as i32)
    }

    /// An integer array (e.g. mesh indices), each value checked to be a 32-bit integer.
    pub fn ints(&self, name: &str) -> Result<Option<(Vec<i64>, &Param)>, ParseError> {
        let Some(p) = self.find(name) else {
            return Ok(None);
        };
        if p.ty != ParamType::Integer {
            return Err(self.type_error(p, "integers"));
        }
        let v = self.numbers(p, "integers")?;
        let out = v
            .iter()
            .enumerate()
            .map(|(i, &x)| self.integer_value(p, i, x))
            .collect::<Result<Vec<_>, _>>()?;
        Ok(Some((out, p)))
    }

    pub fn bool(&self, name: &str, default: bool) -> Result<bool, ParseError> {
        let Some(p) = self.find(name) else {
            return Ok(default);
        };
        let Values::Strings(v) = &p.values else {
            return Err(self.type_error(p, "\"true\" or \"false\""));
        };
        if p.ty != ParamType::Bool || v.len() != 1 {
            return Err(self.type_error(p, "one bool, \"true\" or \"false\""));
        }
        match v[0].as_str() {
            "true" => Ok(true),
            "false" => Ok(false),
            other => Err(self.error(
                p,
                format!("expected \"true\" or \"false\", got \"{other}\""),
            )),
        }
    }

    pub fn string(&self, name: &str) -> Result<Option<String>, ParseError> {
        let Some(p) = self.find(name) else {
            return Ok(None);
        };
        match &p.values {
            Values::Strings(v) if v.len() == 1 && p.ty == ParamType::String => {
                Ok(Some(v[0].clone()))
            }
            _ => Err(self.type_error(p, "one string")),
        }
    }

    pub fn string_or(&self, name: &str, default: &str) -> Result<String, ParseError> {
        Ok(self.string(name)?.unwrap_or_else(|| default.to_string()))
    }

    /// One point, vector or normal.
    pub fn vec3(&self, name: &str, default: Vec3) -> Result<Vec3, ParseError> {
        Ok(match self.vec3s(name)? {
            None => default,
            Some((v, _)) if v.len() == 1 => v[0],
            Some((_, p)) => return Err(self.type_error(p, "one 3-component value")),
        })
    }

    /// A point/vector/normal array.
    pub fn vec3s(&self, name: &str) -> Result<Option<(Vec<Vec3>, &Param)>, ParseError> {
        let Some(p) = self.find(name) else {
            return Ok(None);
        };
        if !matches!(
            p.ty,
            ParamType::Point | ParamType::Vector | ParamType::Normal
        ) {
            return Err(self.type_error(p, "points, vectors or normals"));
        }
        let v = self.numbers(p, "3-component values")?;
        if v.len() % 3 != 0 {
            return Err(self.error(
                p,
                format!("expected a multiple of 3 values, got {}", v.len()),
            ));
        }
        let mut out = Vec::with_capacity(v.len() / 3);
        for (i, c) in v.chunks_exact(3).enumerate() {
            out.push(Vec3::new(
                self.to_f32(p, 3 * i, c[0])?,
                self.to_f32(p, 3 * i + 1, c[1])?,
                self.to_f32(p, 3 * i + 2, c[2])?,
            ));
        }
        Ok(Some((out, p)))
    }

    /// A colour: `color` with 3 values, or one `float` splatted (the seed writes `"float Ks"`).
    pub fn color(&self, name: &str, default: Vec3) -> Result<Vec3, ParseError> {
        let Some(p) = self.find(name) else {
            return Ok(default);
        };
        self.color_of(p)
    }

    fn color_of(&self, p: &Param) -> Result<Vec3, ParseError> {
        match p.ty {
            ParamType::Color => {
                let v = self.exactly(p, 3, "3 color components")?;
                Ok(Vec3::new(
                    self.to_f32(p, 0, v[0])?,
                    self.to_f32(p, 1, v[1])?,
                    self.to_f32(p, 2, v[2])?,
                ))
            }
            ParamType::Float | ParamType::Integer => {
                let v = self.exactly(p, 1, "one float or a color")?;
                Ok(Vec3::splat(self.to_f32(p, 0, v[0])?))
            }
            _ => Err(self.type_error(p, "a color")),
        }
    }

    /// A texture reference: `"texture Kd" "name"` or a bare string given to a color or float.
    fn texture_name(&self, p: &Param) -> Result<Option<ConstOrTextureName>, ParseError> {
        match &p.values {
            Values::Strings(v)
                if matches!(
                    p.ty,
                    ParamType::Texture | ParamType::Color | ParamType::Float
                ) =>
            {
                if v.len() != 1 {
                    return Err(self.type_error(p, "one texture name"));
                }
                Ok(Some(ConstOrTextureName::Named {
                    name: v[0].clone(),
                    pos: p.pos.clone(),
                }))
            }
            _ if p.ty == ParamType::Texture => Err(self.type_error(p, "one texture name")),
            _ => Ok(None),
        }
    }

    pub fn tex_color(&self, name: &str, default: Vec3) -> Result<ConstOrTextureName, ParseError> {
        let Some(p) = self.find(name) else {
            return Ok(ConstOrTextureName::Const(default));
        };
        if let Some(t) = self.texture_name(p)? {
            return Ok(t);
        }
        Ok(ConstOrTextureName::Const(self.color_of(p)?))
    }

    pub fn tex_float(&self, name: &str, default: f32) -> Result<ConstOrTextureName, ParseError> {
        let Some(p) = self.find(name) else {
            return Ok(ConstOrTextureName::Const(Vec3::splat(default)));
        };
        if let Some(t) = self.texture_name(p)? {
            return Ok(t);
        }
        if !matches!(p.ty, ParamType::Float | ParamType::Integer) {
            return Err(self.type_error(p, "one float or a texture name"));
        }
        let v = self.exactly(p, 1, "one float")?;
        Ok(ConstOrTextureName::Const(Vec3::splat(
            self.to_f32(p, 0, v[0])?,
        )))
    }

    /// The number of values of a parameter, if present (without marking it used).
    pub fn count(&self, name: &str) -> Option<usize> {
        self.params
            .iter()
            .rev()
            .find(|p| p.name == name)
            .map(|p| p.values.len())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pos() -> Pos {
        Pos::new("t.lxs", 1, 1)
    }

    fn list(params: Vec<(ParamType, &str, Values)>) -> ParamList {
        ParamList::new(
            "Test".into(),
            params
                .into_iter()
                .map(|(t, n, v)| Param::new(t, n.into(), v, pos()))
                .collect(),
        )
    }

    #[test]
    fn typed_access_and_defaults() {
        let l = list(vec![
            (ParamType::Float, "fov", Values::Numbers(vec![45.0])),
            (ParamType::Integer, "n", Values::Numbers(vec![7.0])),
            (ParamType::Bool, "b", Values::Strings(vec!["true".into()])),
            (ParamType::Float, "Ks", Values::Numbers(vec![0.4])),
            (ParamType::Color, "Kd", Values::Strings(vec!["tex".into()])),
        ]);
        assert_eq!(l.float("fov", 90.0).unwrap(), 45.0);
        assert_eq!(l.float("missing", 90.0).unwrap(), 90.0);
        assert_eq!(l.int("n", 0).unwrap(), 7);
        assert!(l.bool("b", false).unwrap());
        assert_eq!(l.color("Ks", Vec3::ONE).unwrap(), Vec3::splat(0.4));
        assert!(
            matches!(l.tex_color("Kd", Vec3::ONE).unwrap(), ConstOrTextureName::Named { name, .. } if name == "tex")
        );
        assert!(l.params.iter().all(Param::is_used), "every parameter read");
    }

    #[test]
    fn wrong_types_counts_and_ranges_name_the_parameter() {
        let l = list(vec![
            (ParamType::String, "fov", Values::Strings(vec!["x".into()])),
            (ParamType::Color, "Kd", Values::Numbers(vec![1.0, 2.0])),
            (
                ParamType::Float,
                "big",
                Values::Numbers(vec![f64::INFINITY]),
            ),
            (ParamType::Integer, "i", Values::Numbers(vec![1e12])),
            (ParamType::Integer, "f", Values::Numbers(vec![1.5])),
        ]);
        let e = l.float("fov", 1.0).unwrap_err().to_string();
        assert!(e.contains("string fov"), "{e}");
        let e = l.color("Kd", Vec3::ONE).unwrap_err().to_string();
        assert!(e.contains("color Kd") && e.contains("got 2 values"), "{e}");
        let e = l.float("big", 1.0).unwrap_err().to_string();
        assert!(e.contains("float big") && e.contains("out of range"), "{e}");
        assert!(l.int("i", 0).unwrap_err().to_string().contains("integer i"));
        assert!(l
            .ints("f")
            .unwrap_err()
            .to_string()
            .contains("not an integer"));
    }
}
