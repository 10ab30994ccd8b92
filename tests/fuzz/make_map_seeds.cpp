// Writes the map seed corpus (tests/fuzz/corpus/map/): small map bodies as CSparseMap::serialize
// writes them (a 3-keyframe map with fused points, an erased keyframe and a loop edge, and an empty
// map), so that the fuzzer starts from real saved maps.
// Usage: make_map_seeds OUTPUT_FOLDER
#include <cstdio>
#include <fstream>
#include <random>
#include <sstream>

#include "TestUtils.h"
#include "mrpt_yesslam/data/CSparseMap.h"

int main(int argc, char** argv)
{
	using namespace mrpt_yesslam;
	if (argc != 2)
	{
		std::fprintf(stderr, "usage: make_map_seeds OUTPUT_FOLDER\n");
		return 1;
	}
	const std::string dir = argv[1];
	auto save = [&](const CSparseMap& m, const std::string& name)
	{
		std::ostringstream o(std::ios::binary);
		m.serialize(o);
		std::ofstream(dir + "/" + name, std::ios::binary) << o.str();
	};
	std::mt19937 rng(3);
	std::vector<mrpt::math::TPoint3D> world;
	for (int i = 0; i < 12; i++) world.emplace_back(-1.0 + 0.2 * i, 0.1 * (i % 3), 2.0 + 0.05 * i);
	CSparseMap m;
	m.addKeyFrame(yesslam_test::observeWorld(0, {}, world, std::vector<TPointId>(12, -1), rng), 10.0);
	std::vector<TPointId> ids(12, -1);
	for (int j = 0; j < 8; j++) ids[j] = j;
	m.addKeyFrame(yesslam_test::observeWorld(1, mrpt::poses::CPose3D(0.05, 0, 0, 0, 0, 0), world, ids, rng), 10.0);
	m.addKeyFrame(yesslam_test::observeWorld(2, mrpt::poses::CPose3D(0.1, 0, 0, 0, 0, 0), world, ids, rng), 10.0);
	m.replacePoint(9, m.keyFrame(1).mapPoints[9]);
	m.addLoopEdge(0, 2);
	save(m, "three_keyframes.bin");
	m.eraseKeyFrame(1);
	save(m, "erased_keyframe.bin");
	save(CSparseMap(), "empty.bin");
	return 0;
}
