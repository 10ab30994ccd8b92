#include "mrpt_yesslam/mapio/MapFile.h"

#include <Eigen/Dense>

#include <cmath>
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
constexpr std::size_t kHeader = 8 + 4 + 8;  // magic, version, vocabulary fingerprint

std::string hex(std::uint64_t v)
{
	char buf[20];
	std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(v));
	return buf;
}
}  // namespace

void saveMapFile(const std::string& path, const CSparseMap& map, std::uint64_t vocabularyFingerprint,
				 const CSemanticOcTree* octree, const TWorldFrame& frame, bool durable)
{
	std::ostringstream m(std::ios::binary);
	map.serialize(m);
	saveSerializedMapFile(path, std::move(m).str(), vocabularyFingerprint, octree, frame, durable);
}

void saveSerializedMapFile(const std::string& path, const std::string& serializedMap,
						   std::uint64_t vocabularyFingerprint, const CSemanticOcTree* octree, const TWorldFrame& frame,
						   bool durable)
{
	// The file is composed in one buffer: the head, the map, the octree section and the frame, then
	// the checksum of all of it.
	std::ostringstream head(std::ios::binary);
	head.write(kMagic, 8);
	binio::put<std::uint32_t>(head, kMapFileVersion);
	binio::put<std::uint64_t>(head, vocabularyFingerprint);
	// The semantic OctoMap as its own .ot bytes, with their length (0: none), after its occupancy
	// threshold (a run's is configurable, [DenseMapping] occupancyThreshold, and .ot does not keep it).
	std::string ot;
	if (octree)
	{
		std::ostringstream os(std::ios::binary);
		if (!octree->write(os)) throw InputError(path, "OctoMap could not write the semantic octree");
		ot = std::move(os).str();
	}
	std::ostringstream tail(std::ios::binary);
	binio::put<double>(tail, octree ? octree->getOccupancyThres() : 0.0);
	binio::put<std::uint64_t>(tail, ot.size());
	tail.write(ot.data(), static_cast<std::streamsize>(ot.size()));
	ot = std::string();
	// Version 2: the export frame (kind, how it was levelled, T_world_map as its rotation matrix row
	// by row and its translation: read back exactly, so that a map saved again keeps its bytes).
	binio::put<std::uint8_t>(tail, frame.kind == TWorldFrame::EKind::ZUp ? 1 : 0);
	binio::put<std::uint8_t>(tail, frame.floorSeen ? 1 : 0);
	binio::put<double>(tail, frame.cameraHeight);
	const auto R = frame.worldFromMap.getRotationMatrix();
	for (int r = 0; r < 3; r++)
		for (int c = 0; c < 3; c++) binio::put<double>(tail, R(r, c));
	for (double v : {frame.worldFromMap.x(), frame.worldFromMap.y(), frame.worldFromMap.z()})
		binio::put<double>(tail, v);
	const std::string h = std::move(head).str(), t = std::move(tail).str();
	std::string buf;
	buf.reserve(h.size() + serializedMap.size() + t.size() + 8);
	buf.append(h).append(serializedMap).append(t);
	const std::uint64_t sum = binio::checksum(buf.data(), buf.size());
	buf.append(reinterpret_cast<const char*>(&sum), 8);
	writeFileAtomically(path, buf.data(), buf.size(), durable);
}

TMapFileInfo loadMapFile(const std::string& path, CSparseMap& map, std::uint64_t vocabularyFingerprint,
						 std::unique_ptr<CSemanticOcTree>* octree)
{
	std::ifstream f(path, std::ios::binary | std::ios::ate);
	if (!f) throw InputError(path, "cannot open the map file");
	const auto size = static_cast<std::uint64_t>(f.tellg());
	if (size > (std::uint64_t(1) << 34)) throw InputError(path, "not a yesslam map (larger than 16 GB)");
	std::string buf(static_cast<std::size_t>(size), '\0');
	f.seekg(0);
	if (!f.read(buf.data(), static_cast<std::streamsize>(size))) throw InputError(path, "cannot read the map file");
	if (size < 8 || std::memcmp(buf.data(), kMagic, 8) != 0)
		throw InputError(path, "not a yesslam map (save one with yesslam --save-map)");
	if (size < kHeader + 8) throw InputError(path, "map file is truncated");
	TMapFileInfo info;
	info.bytes = size;
	std::memcpy(&info.version, buf.data() + 8, 4);
	if (info.version == 0 || info.version > kMapFileVersion)
		throw InputError(path, "map format version " + std::to_string(info.version) + ", this build reads up to " +
								   std::to_string(kMapFileVersion));
	std::uint64_t stored;
	std::memcpy(&stored, buf.data() + size - 8, 8);
	if (binio::checksum(buf.data(), size - 8) != stored)
		throw InputError(path, "map file is truncated or corrupt (checksum mismatch)");
	std::memcpy(&info.vocabularyFingerprint, buf.data() + 12, 8);
	// A map saved without a vocabulary, or loaded without one, is fine (its keyframes' words are
	// computed from their descriptors at load, or relocalisation goes without words); two different
	// vocabularies are not: what the map's place recognition was tuned and checked with would change.
	if (info.vocabularyFingerprint && vocabularyFingerprint && info.vocabularyFingerprint != vocabularyFingerprint)
		throw InputError(path, "the map was saved with another vocabulary (fingerprint " +
								   hex(info.vocabularyFingerprint) + ", this run's " + hex(vocabularyFingerprint) +
								   "); load it with the vocabulary it was made with ([LoopClosing] vocabulary)");
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
			if (!in.read(ot.data(), static_cast<std::streamsize>(ot.size())))
				throw std::runtime_error("truncated semantic octree");
			std::istringstream os(ot, std::ios::binary);
			tree = CSemanticOcTree::read(os, "its semantic octree");
			if (!(threshold > 0 && threshold < 1)) throw std::runtime_error("occupancy threshold out of (0, 1)");
			tree->setOccupancyThres(threshold);
		}
		if (info.version >= 2)
		{
			const auto kind = binio::get<std::uint8_t>(in, "the export frame's kind");
			const auto floor = binio::get<std::uint8_t>(in, "the export frame's levelling");
			if (kind > 1 || floor > 1) throw std::runtime_error("unknown export frame kind");
			info.worldFrame.kind = kind ? TWorldFrame::EKind::ZUp : TWorldFrame::EKind::Optical;
			info.worldFrame.floorSeen = floor == 1;
			info.worldFrame.cameraHeight = binio::get<double>(in, "the first camera's height");
			double v[12];
			for (double& x : v)
			{
				x = binio::get<double>(in, "the export frame's T_world_map");
				if (!std::isfinite(x)) throw std::runtime_error("export frame is not finite");
			}
			mrpt::math::CMatrixDouble33 R;
			mrpt::math::CVectorFixedDouble<3> t;
			for (int k = 0; k < 9; k++) R(k / 3, k % 3) = v[k];
			for (int k = 0; k < 3; k++) t[k] = v[9 + k];
			if ((R.asEigen() * R.asEigen().transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-6 ||
				R.asEigen().determinant() < 0)
				throw std::runtime_error("export frame's rotation is not a rotation");
			info.worldFrame.worldFromMap = mrpt::poses::CPose3D(R, t);
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
