pub mod concealed;
pub mod dp_truth;
pub mod open_world;
pub mod open_world_discovery;
pub mod surface;
