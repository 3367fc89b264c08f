pub mod open_world;
pub mod open_world_discovery;
