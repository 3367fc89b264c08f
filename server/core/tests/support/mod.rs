pub mod open_world;
pub mod open_world_discovery;
pub mod dp_truth;
