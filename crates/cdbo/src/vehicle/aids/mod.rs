//! The driver's aids as cdbo's TORCS robot has them: the launch clutch, traction control and
//! ABS. They are the robot's decisions, which it can only take at the game's 50 Hz driver
//! steps; each is defined here for the robot's `torcs-robot/drive.hpp`, which
//! `tests/robot_drive.rs` checks against it, and cdbo's simulator drives a car the robot
//! drives ([`crate::car::Car::torcs_robot`]) with them ([`crate::vehicle`]).

pub mod abs;
pub mod launch;
pub mod traction;
