#pragma once
// The map section of a map file: written deterministically, and read into a new store that is
// checked in full (every reference both ways, finite poses, a spanning tree without cycles)
// before anything can use it. Private to the library.
#include <iosfwd>
#include <memory>

#include "SparseMapStore.h"

namespace mrpt_yesslam::sparse_map
{
/** See CSparseMap::serialize (the caller holds the map's lock). */
void serialize(const TSparseMapStore& s, std::ostream& out);
/** See CSparseMap::deserialize: a new store, or std::runtime_error. */
std::unique_ptr<TSparseMapStore> deserialize(std::istream& in);
}  // namespace mrpt_yesslam::sparse_map
