#pragma once
// Saved maps (.ysm): the sparse map of a run, to be loaded by a later run that localises in it
// (issue 17). One file: a magic, a format version, the fingerprint of the vocabulary the keyframes'
// words came from, the map (CSparseMap::serialize) and a checksum of everything before it, so that a
// damaged, cut or foreign file is refused in one line before any of it is used.
#include <cstdint>
#include <string>

#include <memory>

#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/dense/CSemanticOcTree.h"
#include "mrpt_yesslam/io/WorldFrame.h"

namespace mrpt_yesslam
{
/** What a map file's header says (yesslam-map, error messages). */
struct TMapFileInfo
{
	std::uint32_t version = 0;
	std::uint64_t vocabularyFingerprint = 0;  //!< 0: saved without a vocabulary
	std::uint64_t bytes = 0;
	std::uint64_t octreeBytes = 0;  //!< the semantic OctoMap's .ot inside (0 = none)
	/** The frame the map's exports (and its octree) are in; version 1 files: optical. */
	TWorldFrame worldFrame;
};

/** Format version of .ysm files; readers refuse newer ones. 2: the export frame after the octree
 * (version 1 files are read as optical: their octree was built in the map's own frame). */
constexpr std::uint32_t kMapFileVersion = 2;

/** Writes `map` to `path` atomically (also what Ctrl-C saves); `vocabularyFingerprint` is
 * CVocabulary::fingerprint() of the run's vocabulary, 0 without one; `octree`, the run's semantic
 * OctoMap, is stored with it when given, in `frame` (the frame the octree was built in and later
 * runs export in). `durable`: synced to the disk (a checkpoint, on a thread of its own). Throws
 * InputError naming the file. */
void saveMapFile(const std::string& path, const CSparseMap& map, std::uint64_t vocabularyFingerprint,
				 const CSemanticOcTree* octree = nullptr, const TWorldFrame& frame = {}, bool durable = false);
/** saveMapFile with the map already serialized (CSparseMap::serialize's bytes): a checkpoint
 * copies the map under a lock and writes the file after it. */
void saveSerializedMapFile(const std::string& path, const std::string& serializedMap,
						   std::uint64_t vocabularyFingerprint, const CSemanticOcTree* octree, const TWorldFrame& frame,
						   bool durable);

/** Reads a map file into `map` (replacing its content; after an error it is unspecified). `vocabularyFingerprint`: this
 * run's vocabulary (0: none); a map saved under another vocabulary is refused (saved or loaded without one is
 * accepted). Throws InputError naming the file for a missing file, a foreign or newer-format file, a truncated or
 * corrupt one (checksum) and inconsistent content. The stored semantic OctoMap is checked too, and returned in `octree`
 * when asked for (null when the file has none). */
TMapFileInfo loadMapFile(const std::string& path, CSparseMap& map, std::uint64_t vocabularyFingerprint,
						 std::unique_ptr<CSemanticOcTree>* octree = nullptr);
}  // namespace mrpt_yesslam
