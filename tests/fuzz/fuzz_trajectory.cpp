// Fuzz target: TUM trajectory parsing, then ATE/RPE of the parsed trajectory against itself and
// a shifted copy (the evaluator must survive any finite numbers the parser accepts).
#include <cstdint>
#include <string>

#include "mrpt_yesslam/eval/TrajectoryEvaluator.h"
#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/util/Error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size)
{
	using namespace mrpt_yesslam;
	const std::string text(reinterpret_cast<const char*>(data), size);
	try
	{
		const TTrajectory t = parseTumTrajectory(text, "fuzz.txt");
		if (t.size() >= 3 && t.size() < 2000)
		{
			TTrajectory other = t;
			for (auto& p : other) p.tx += 0.5;
			computeAte(t, other, TEvalOptions{});
			computeRpe(t, other, TEvalOptions{});
		}
	}
	catch (const InputError&)
	{
		// Rejected input: the expected outcome for most fuzz inputs.
	}
	return 0;
}
