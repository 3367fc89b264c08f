pub mod open_world;
