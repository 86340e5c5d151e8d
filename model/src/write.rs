use crate::Model;
pub fn to_urdf(_m: &Model) -> String { todo!() }
