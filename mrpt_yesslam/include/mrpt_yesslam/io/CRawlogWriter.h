#pragma once
// Writes an observation-only rawlog atomically: frames go to a temporary file that is renamed to
// the final name by commit(), so an interrupted run leaves no truncated .rawlog behind.
#include <mrpt/io/CFileGZOutputStream.h>
#include <mrpt/obs/CObservation.h>

#include <memory>
#include <string>

namespace mrpt_yesslam
{
/** Appends observations to a new .rawlog (gz level 1, as MRPT's own tools write them). */
class CRawlogWriter
{
   public:
	/** Opens "<path>.tmp.<pid>" for writing; throws InputError naming `path` if it cannot. */
	explicit CRawlogWriter(const std::string& path, int compressionLevel = 1);
	/** Removes the temporary file unless commit() was called. */
	~CRawlogWriter();
	CRawlogWriter(const CRawlogWriter&) = delete;
	CRawlogWriter& operator=(const CRawlogWriter&) = delete;

	/** Serializes one observation; throws InputError on a write failure. */
	void write(const mrpt::obs::CObservation& obs);
	/** Closes the file and renames it into place; returns its size in bytes. */
	std::uintmax_t commit();
	/** Observations written so far. */
	std::size_t count() const { return count_; }

   private:
	std::string path_, tmp_;
	std::string target_;   //!< path_ with links followed
	bool direct_ = false;  //!< a device or pipe: written in place
	int fd_ = -1;          //!< a descriptor of ours (/dev/stdout): written to tmp_, appended to it on commit
	std::unique_ptr<mrpt::io::CFileGZOutputStream> out_;
	std::size_t count_ = 0;
	bool committed_ = false;
};
}  // namespace mrpt_yesslam
