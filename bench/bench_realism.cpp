// Sensor statistics of RGB-D sequences (sim/CSensorStatistics), to hold the simulator against real
// frames: depth noise against distance, valid depth, flying pixels, texture, sharpness.
// usage: bench_realism [--step K] [--max-frames N] [--camera C] FOLDER   (a TUM folder or rawlog)
// Prints "key: value" lines; bench/bench_realism.sh puts sequences side by side.
#include <cstdio>
#include <string>

#include "mrpt_yesslam/sim/CSensorStatistics.h"
#include "mrpt_yesslam/io/CInputSource.h"
#include "mrpt_yesslam/io/RgbdObservation.h"

using namespace mrpt_yesslam;

int main(int argc, char** argv)
{
	int step = 1, maxFrames = 0;
	std::string input;
	CInputSource::TOptions io;
	for (int a = 1; a < argc; a++)
	{
		const std::string s = argv[a];
		if (s == "--step" && a + 1 < argc)
			step = std::max(1, std::stoi(argv[++a]));
		else if (s == "--max-frames" && a + 1 < argc)
			maxFrames = std::stoi(argv[++a]);
		else if (s == "--camera" && a + 1 < argc)
			io.camera = argv[++a];
		else
			input = s;
	}
	if (input.empty())
	{
		std::fprintf(stderr, "usage: bench_realism [--step K] [--max-frames N] [--camera C] FOLDER\n");
		return 2;
	}
	try
	{
		auto src = openInputSource(input, io);
		CSensorStatistics st;
		int k = 0;
		while (auto obs = src->next())
		{
			if (maxFrames > 0 && k >= maxFrames) break;
			if (k++ % step) continue;
			st.addFrame(obs->intensityImage.asCvMatRef(), depthInMetres(*obs));
		}
		std::fputs(CSensorStatistics::format(st.result()).c_str(), stdout);
	}
	catch (const std::exception& e)
	{
		std::fprintf(stderr, "bench_realism: error: %s\n", e.what());
		return 1;
	}
	return 0;
}
