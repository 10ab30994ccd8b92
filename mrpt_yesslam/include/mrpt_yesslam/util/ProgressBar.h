#pragma once
// A progress indicator for long runs: a redrawn bar on a terminal, a line every few seconds
// otherwise (so CI logs and redirected output stay readable).
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <string>

namespace mrpt_yesslam
{
/** Prints progress of a job of `total` steps (0 when unknown) to stderr. */
class ProgressBar
{
   public:
	/** `label` prefixes every line; `enabled=false` makes every call a no-op (for --quiet). */
	ProgressBar(std::string label, std::size_t total, bool enabled = true);
	/** Reports that `done` steps are complete; `extra` is appended (e.g. "fps 30.1"). */
	void update(std::size_t done, const std::string& extra = {});
	/** Sets the total once it is known (0 = unknown). */
	void setTotal(std::size_t total) { total_ = total; }
	/** Prints the final state and a newline. */
	void finish(const std::string& extra = {});

   private:
	void draw(bool final, const std::string& extra);

	std::string label_;
	std::size_t total_;
	std::size_t done_ = 0;
	bool enabled_;
	bool tty_;
	std::chrono::steady_clock::time_point start_, lastDraw_;
};
}  // namespace mrpt_yesslam
