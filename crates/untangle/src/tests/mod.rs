mod energy;
mod repair;
