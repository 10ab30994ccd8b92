#include "mrpt_yesslam/io/MapFile.h"

#include <cstring>
#include <fstream>
#include <sstream>

#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/BinaryIO.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
namespace
{
constexpr char kMagic[8] = {'Y', 'E', 'S', 'S', 'L', 'A', 'M', 'M'};
constexpr std::size_t kHeader = 8 + 4 + 8;	// magic, version, vocabulary fingerprint

std::string hex(std::uint64_t v)
{
	char buf[20];
	std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(v));
	return buf;
}
}  // namespace

void saveMapFile(const std::string& path, const CSparseMap& map, std::uint64_t vocabularyFingerprint, const CSemanticOcTree* octree)
{
	std::ostringstream o(std::ios::binary);
	o.write(kMagic, 8);
	binio::put<std::uint32_t>(o, kMapFileVersion);
	binio::put<std::uint64_t>(o, vocabularyFingerprint);
	map.serialize(o);
	// The semantic OctoMap as its own .ot bytes, with their length (0: none), after its occupancy
	// threshold (a run's is configurable, [DenseMapping] occupancyThreshold, and .ot does not keep it).
	std::string ot;
	if (octree)
	{
		std::ostringstream os(std::ios::binary);
		if (!octree->write(os)) throw InputError(path, "OctoMap could not write the semantic octree");
		ot = std::move(os).str();
	}
	binio::put<double>(o, octree ? octree->getOccupancyThres() : 0.0);
	binio::put<std::uint64_t>(o, ot.size());
	o.write(ot.data(), static_cast<std::streamsize>(ot.size()));
	std::string buf = std::move(o).str();
	const std::uint64_t sum = binio::checksum(buf.data(), buf.size());
	buf.append(reinterpret_cast<const char*>(&sum), 8);
	writeFileAtomically(path, buf);
}

TMapFileInfo loadMapFile(const std::string& path, CSparseMap& map, std::uint64_t vocabularyFingerprint, std::unique_ptr<CSemanticOcTree>* octree)
{
	std::ifstream f(path, std::ios::binary | std::ios::ate);
	if (!f) throw InputError(path, "cannot open the map file");
	const auto size = static_cast<std::uint64_t>(f.tellg());
	if (size > (std::uint64_t(1) << 34)) throw InputError(path, "not a yesslam map (larger than 16 GB)");
	std::string buf(static_cast<std::size_t>(size), '\0');
	f.seekg(0);
	if (!f.read(buf.data(), static_cast<std::streamsize>(size))) throw InputError(path, "cannot read the map file");
	if (size < 8 || std::memcmp(buf.data(), kMagic, 8) != 0) throw InputError(path, "not a yesslam map (save one with yesslam --save-map)");
	if (size < kHeader + 8) throw InputError(path, "map file is truncated");
	TMapFileInfo info;
	info.bytes = size;
	std::memcpy(&info.version, buf.data() + 8, 4);
	if (info.version == 0 || info.version > kMapFileVersion)
		throw InputError(path, "map format version " + std::to_string(info.version) + ", this build reads up to " + std::to_string(kMapFileVersion));
	std::uint64_t stored;
	std::memcpy(&stored, buf.data() + size - 8, 8);
	if (binio::checksum(buf.data(), size - 8) != stored)
		throw InputError(path, "map file is truncated or corrupt (checksum mismatch)");
	std::memcpy(&info.vocabularyFingerprint, buf.data() + 12, 8);
	// A map saved without a vocabulary, or loaded without one, is fine (its keyframes' words are
	// computed from their descriptors at load, or relocalisation goes without words); two different
	// vocabularies are not: what the map's place recognition was tuned and checked with would change.
	if (info.vocabularyFingerprint && vocabularyFingerprint && info.vocabularyFingerprint != vocabularyFingerprint)
		throw InputError(path, "the map was saved with another vocabulary (fingerprint " + hex(info.vocabularyFingerprint) + ", this run's " +
								   hex(vocabularyFingerprint) + "); load it with the vocabulary it was made with ([LoopClosing] vocabulary)");
	std::istringstream in(buf.substr(kHeader, size - kHeader - 8), std::ios::binary);
	std::unique_ptr<CSemanticOcTree> tree;
	// Read aside and put in place only once the octree section has been read too.
	CSparseMap staged;
	try
	{
		staged.deserialize(in);
		const double threshold = binio::get<double>(in, "the semantic octree's occupancy threshold");
		info.octreeBytes = binio::get<std::uint64_t>(in, "the semantic octree's length");
		if (info.octreeBytes > size) throw std::runtime_error("implausible semantic octree length");
		if (info.octreeBytes)
		{
			std::string ot(static_cast<std::size_t>(info.octreeBytes), '\0');
			if (!in.read(ot.data(), static_cast<std::streamsize>(ot.size()))) throw std::runtime_error("truncated semantic octree");
			std::istringstream os(ot, std::ios::binary);
			tree = CSemanticOcTree::read(os, "its semantic octree");
			if (!(threshold > 0 && threshold < 1)) throw std::runtime_error("occupancy threshold out of (0, 1)");
			tree->setOccupancyThres(threshold);
		}
	}
	catch (const std::exception& e)
	{
		throw InputError(path, std::string("map file is inconsistent (") + e.what() + ")");
	}
	if (in.peek() != std::char_traits<char>::eof()) throw InputError(path, "map file has data after the map");
	map.swapContent(staged);
	if (octree) *octree = std::move(tree);
	return info;
}
}  // namespace mrpt_yesslam
