#include "mrpt_yesslam/system/CRunJournal.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "mrpt_yesslam/io/Trajectory.h"
#include "mrpt_yesslam/system/CYesSlamSystem.h"
#include "mrpt_yesslam/system/SlamExport.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
namespace fs = std::filesystem;

namespace
{
// Writes all of `text` to `fd` (a signal may interrupt it); 0, or the errno of the failure (-1: nothing written).
int writeAll(int fd, const std::string& text)
{
	for (std::size_t done = 0; done < text.size();)
	{
		const ssize_t n = ::write(fd, text.data() + done, text.size() - done);
		if (n < 0 && errno == EINTR) continue;
		if (n <= 0) return n < 0 ? errno : -1;
		done += static_cast<std::size_t>(n);
	}
	return 0;
}

// A new file holding `head`, open for appending; throws InputError naming it.
int openJournalFile(const std::string& path, const std::string& head)
{
	const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_APPEND | O_CLOEXEC, 0644);
	const int e = fd < 0 ? errno : writeAll(fd, head);
	if (e == 0) return fd;
	if (fd >= 0) ::close(fd);
	throw InputError(path,
					 std::string("cannot write the run's journal: ") + (e > 0 ? std::strerror(e) : "nothing written"));
}
}  // namespace

CRunJournal::CRunJournal(const std::string& dir) : dir_(dir)
{
	const fs::path d(dir);
	// First, so that whatever else is in the folder is never taken for a finished run.
	writeFileAtomically((d / "stats.json").string(),
						"{\n  \"complete\": false,\n  \"stop_reason\": \"the run has not ended: it is still running, "
						"or it was killed; trajectory_online.txt "
						"and frames.csv hold the frames it journaled (poses in the map's own frame), and its end "
						"replaces every file\"\n}\n");
	trajectoryFd_ =
		openJournalFile((d / "trajectory_online.txt").string(),
						formatTumTrajectory({},
											"camera pose (T_w_c) of every frame that has one as the run had it then "
											"(tracked or coasted): what a robot had\n"
											"journal of a run that has not ended (still running, or killed): its end "
											"replaces this file with the poses in the outputs' "
											"world frame (found at the end)\n"
											"poses in the map's own frame: its first keyframe's camera (x right, y "
											"down, z forward), or a loaded map's\n"
											"T_world_map: 0 0 0 0 0 0 1 (the map's frame itself)"));
	try
	{
		framesFd_ = openJournalFile((d / "frames.csv").string(), formatFrameLogCsv({}));
	}
	catch (...)
	{
		::close(trajectoryFd_);
		throw;
	}
}

CRunJournal::~CRunJournal()
{
	close();
}

bool CRunJournal::append(int fd, const std::string& text, const std::string& name)
{
	// One write of whole lines per file and frame, handed to the kernel at once: a killed process
	// loses none of it. Only a write that spans two pages of the file can be cut by the kill (or a
	// full disk) at the page's end, leaving its last line without a newline; a short write ends the journal.
	if (const int e = writeAll(fd, text); e != 0)
	{
		failure_ = (fs::path(dir_) / name).string() + ": the journal stopped after " + std::to_string(frames_) +
				   " frames: " + (e > 0 ? std::strerror(e) : "nothing written");
		close();
		return false;
	}
	return true;
}

bool CRunJournal::update(const CYesSlamSystem& sys)
{
	if (trajectoryFd_ < 0) return false;
	const auto part = sys.framesSince(frames_);
	if (part.rows.empty()) return true;
	// The rows first: a kill between the two writes leaves a row without its pose, never a pose
	// without its row.
	if (!append(framesFd_, formatFrameLogCsv(part.rows, false), "frames.csv")) return false;
	if (!part.online.empty() && !append(trajectoryFd_, formatTumTrajectory(part.online), "trajectory_online.txt"))
		return false;
	frames_ += part.rows.size();
	return true;
}

void CRunJournal::close()
{
	for (int* fd : {&trajectoryFd_, &framesFd_})
		if (*fd >= 0)
		{
			::close(*fd);
			*fd = -1;
		}
}
}  // namespace mrpt_yesslam
