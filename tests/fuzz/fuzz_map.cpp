// Fuzz target: saved maps (.ysm). The input is a map body as CSparseMap::serialize writes it; it is
// read directly (the content checks behind the file's checksum) and then used as tracking and
// saving would use it, and it is also wrapped into a file with a valid header and checksum and read
// through loadMapFile, as yesslam --load-map does. A damaged body must be refused with an
// exception, never crash or hang; an accepted one must carry relocalisation and tracking (an
// exception escaping them other than a one-line runtime_error fails the replay).
#include <unistd.h>

#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

#include "mrpt_yesslam/data/CSparseMap.h"
#include "mrpt_yesslam/mapio/MapFile.h"
#include "mrpt_yesslam/tracking/CTracker.h"
#include "mrpt_yesslam/util/BinaryIO.h"
#include "mrpt_yesslam/util/Error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	using namespace mrpt_yesslam;
	const std::string body(reinterpret_cast<const char*>(data), size);
	try
	{
		CSparseMap m;
		std::istringstream in(body, std::ios::binary);
		m.deserialize(in);
		// What a loaded map goes through: poses (trajectory, scene), local maps, the essential
		// graph, and saving again.
		(void)m.keyFramePoses();
		(void)m.points();
		(void)m.essentialGraph(15);
		for (const TKeyFrameId id : m.keyFrameIds())
		{
			(void)m.pointsOfKeyFrames(m.localKeyFrames({}, id, 40));
			(void)m.keyFramePoints(id);
			(void)m.numKeyFramePoints(id, 2);
		}
		std::ostringstream out(std::ios::binary);
		m.serialize(out);
		// Relocalisation and tracking in it, with each keyframe's own features as the frame (issue
		// 28: a map that passed validation crashed the matcher): a frame is placed, then tracked again.
		for (const TKeyFrameId id : m.keyFrameIds())
		{
			const CKeyFrame kf = m.keyFrame(id);
			if (!kf.features) continue;
			CTracker tracker(CTracker::TOptions(), m);
			tracker.setMapReadOnly(true);
			for (std::size_t k = 0; k < 2; k++)
			{
				auto f = std::make_shared<TFrame>();
				f->id = k;
				f->camera = kf.camera;
				f->features = *kf.features;
				tracker.track(*f);
				tracker.setLastFrame(f);
			}
			break;  // one keyframe: the map's content is what is under test
		}
	}
	catch (const std::runtime_error&)
	{
		// Refused: the expected outcome for most inputs.
	}
	// The same body in a well-formed file.
	std::string file("YESSLAMM", 8);
	const std::uint32_t version = kMapFileVersion;
	const std::uint64_t vocabulary = 0;
	file.append(reinterpret_cast<const char*>(&version), 4);
	file.append(reinterpret_cast<const char*>(&vocabulary), 8);
	file += body;
	file += std::string(16, '\0');  // no semantic octree (threshold 0, length 0)
	const std::uint64_t sum = binio::checksum(file.data(), file.size());
	file.append(reinterpret_cast<const char*>(&sum), 8);
	const std::string path = "/tmp/yesslam_fuzz_map_" + std::to_string(::getpid()) + ".ysm";
	std::ofstream(path, std::ios::binary) << file;
	try
	{
		CSparseMap m;
		loadMapFile(path, m, 0);
	}
	catch (const InputError&)
	{
	}
	std::remove(path.c_str());
	return 0;
}
