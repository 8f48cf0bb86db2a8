#pragma once
/// @file
/// The normal-cone algebra (public contract): see clothcd/geometry/cone.hpp.
#include "clothcd/geometry/cone.hpp"
