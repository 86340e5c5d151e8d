//! URDF front end (helper writes this).
use crate::{Model, ModelErrors};
pub fn parse_urdf(_text: &str) -> Result<Model, ModelErrors> { todo!() }
pub fn load_urdf(_path: &std::path::Path) -> Result<Model, ModelErrors> { todo!() }
