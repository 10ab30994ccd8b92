#pragma once
// What a run has done so far, kept in its output folder as it goes (issue 68 item 1): a process
// killed by kill -9 or the out-of-memory killer keeps every frame's online pose and frames.csv row
// up to the last frame it finished. The end of the run replaces these files atomically with the
// complete outputs (CYesSlamSystem's trajectories, frames.csv, stats.json).
#include <cstddef>
#include <string>

namespace mrpt_yesslam
{
class CYesSlamSystem;

/** Appends each new frame's online pose to trajectory_online.txt and its row to frames.csv in
 * `dir`, in whole lines, and leaves a stats.json saying "complete": false until the run's own
 * outputs replace it. The poses are in the map's own frame (the header says so): the outputs'
 * z-up world frame is only found at the end of the run. Not thread-safe: one caller. */
class CRunJournal
{
   public:
	/** Starts the journal in `dir` (which must exist), replacing what an earlier run left there
	 * under those names; throws InputError naming the file it cannot write. */
	explicit CRunJournal(const std::string& dir);
	~CRunJournal();
	CRunJournal(const CRunJournal&) = delete;
	CRunJournal& operator=(const CRunJournal&) = delete;

	/** Appends what `sys` processed since the last call, handed to the kernel at once (each call's
	 * lines in one write per file; not synced to the disk: a sync on the tracking thread could
	 * stall a live camera behind a recording's writes). A write that fails ends the journal (the
	 * run goes on): false, and failure() says why. */
	bool update(const CYesSlamSystem& sys);
	/** Closes the files (before the run's final outputs replace them); idempotent. */
	void close();
	/** Frames journaled so far. */
	std::size_t frames() const { return frames_; }
	/** Why the journal stopped (empty while it works). */
	const std::string& failure() const { return failure_; }

   private:
	bool append(int fd, const std::string& text, const std::string& name);

	std::string dir_;
	int trajectoryFd_ = -1, framesFd_ = -1;
	std::size_t frames_ = 0;
	std::string failure_;
};
}  // namespace mrpt_yesslam
