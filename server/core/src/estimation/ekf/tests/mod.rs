mod generic;
mod supply;
