//! Random haul-road study (todo)
