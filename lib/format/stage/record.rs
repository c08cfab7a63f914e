//! The records of a stage file: the element type and payload of an array record
//! and the named array it holds; the header's first word.

/// The first word of every stage file's header line.
pub(super) const MAGIC: &str = "splinecontact";

/// Element type of an array record.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Dtype {
    F64 = 1,
    U32 = 2,
    U64 = 3,
    I32 = 4,
    U8 = 5,
}

impl Dtype {
    pub(super) fn from_u8(v: u8) -> Option<Self> {
        Some(match v {
            1 => Self::F64,
            2 => Self::U32,
            3 => Self::U64,
            4 => Self::I32,
            5 => Self::U8,
            _ => return None,
        })
    }
    pub fn size(self) -> usize {
        match self {
            Self::F64 | Self::U64 => 8,
            Self::U32 | Self::I32 => 4,
            Self::U8 => 1,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            Self::F64 => "f64",
            Self::U32 => "u32",
            Self::U64 => "u64",
            Self::I32 => "i32",
            Self::U8 => "u8",
        }
    }
}

/// Typed payload of an array record.
#[derive(Debug, Clone, PartialEq)]
pub enum ArrayData {
    F64(Vec<f64>),
    U32(Vec<u32>),
    U64(Vec<u64>),
    I32(Vec<i32>),
    U8(Vec<u8>),
}

impl ArrayData {
    pub fn dtype(&self) -> Dtype {
        match self {
            Self::F64(_) => Dtype::F64,
            Self::U32(_) => Dtype::U32,
            Self::U64(_) => Dtype::U64,
            Self::I32(_) => Dtype::I32,
            Self::U8(_) => Dtype::U8,
        }
    }
    pub fn len(&self) -> usize {
        match self {
            Self::F64(v) => v.len(),
            Self::U32(v) => v.len(),
            Self::U64(v) => v.len(),
            Self::I32(v) => v.len(),
            Self::U8(v) => v.len(),
        }
    }
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// A named n-dimensional array (row-major).
#[derive(Debug, Clone, PartialEq)]
pub struct Array {
    pub name: String,
    pub dims: Vec<u64>,
    pub data: ArrayData,
}
