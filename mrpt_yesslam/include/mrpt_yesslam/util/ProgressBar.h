#pragma once
// A progress indicator for long runs: a redrawn bar on a terminal, a line every few seconds
// otherwise (so CI logs and redirected output stay readable).
#include <chrono>
#include <cstddef>
#include <cstdio>
#include <optional>
#include <string>

namespace mrpt_yesslam
{
/** Prints progress of a job of `total` steps (0 when unknown) to stderr. */
class ProgressBar
{
   public:
	/** `label` prefixes every line; `enabled=false` makes every call a no-op (for --quiet);
	 * `rateUnit` follows the rate ("/s", " fps"). */
	ProgressBar(std::string label, std::size_t total, bool enabled = true, std::string rateUnit = "/s");
	/** The rate's clock starts now (at construction otherwise): the work being counted begins. */
	void startClock();
	/** The rate's clock stops now: later lines (finish) give the rate of the work counted until now,
	 * not of what follows it (writing the outputs). */
	void stopClock();
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
	std::string rateUnit_;
	std::chrono::steady_clock::time_point start_, lastDraw_;
	std::optional<std::chrono::steady_clock::time_point> stop_;
};
}  // namespace mrpt_yesslam
