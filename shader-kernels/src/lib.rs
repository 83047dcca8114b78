//! Compute entry points.
#![no_std]
