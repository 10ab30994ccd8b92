#pragma once
// The outputs of a yesslam run (SlamJob): the trajectories, frames.csv, stats.json and the
// configuration first, then the dense map, the map file and the scene, each written atomically.
#include <functional>
#include <string>

#include "mrpt_yesslam/jobs/SlamJob.h"

namespace mrpt_yesslam
{
class CYesSlamSystem;

/** Lets go of what no output needs before the outputs (the run's peak of memory was there): the
 * frames kept for keyframe choice, the detector's network, and glibc's free arenas. */
void releaseBeforeOutputs(CYesSlamSystem& sys);

/** Writes the outputs of `sys` into `dir` and fills `sum`'s output figures. `stop`: why the run
 * ended early (empty: it read the whole input, or --max-frames): stats.json then starts with
 * "complete": false, the reason and the frames done. `mapPath`: --save-map's file (empty: none).
 * `abort`: asked before each slow output (a second Ctrl-C): true skips it, and stats.json names
 * what was skipped. */
void writeSlamOutputs(const CYesSlamSystem& sys, const std::string& dir, TSlamJobSummary& sum,
					  const std::string& stop = {}, const std::string& mapPath = {},
					  const std::function<bool()>& abort = {});
}  // namespace mrpt_yesslam
