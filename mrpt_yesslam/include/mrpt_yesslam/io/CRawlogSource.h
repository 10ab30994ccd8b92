#pragma once
// Frames from an MRPT rawlog, streamed from disk. Both rawlog formats are read: a plain sequence of
// observations, and action/sensory-frame pairs (every CObservation3DRangeScan of a frame is
// returned). External images are found through CRawlog::detectImagesDirectory.
#include <mrpt/io/CFileGZInputStream.h>
#include <mrpt/obs/CObservation3DRangeScan.h>

#include <deque>
#include <memory>

#include "mrpt_yesslam/io/CInputSource.h"

namespace mrpt_yesslam
{
/** Streams CObservation3DRangeScan frames out of a .rawlog file. */
class CRawlogSource : public CInputSource
{
   public:
	/** Opens the file; throws InputError if it is missing or not a rawlog. */
	explicit CRawlogSource(const std::string& path, const TOptions& opts = {});
	mrpt::obs::CObservation3DRangeScan::Ptr next() override;
	std::size_t skipped() const override { return skipped_; }
	const std::string& path() const override { return path_; }
	/** Entries (objects) read so far, for messages. */
	std::size_t entriesRead() const { return entries_; }

   private:
	/** Reads the next serialized object; nullptr at a clean end of file. A stream that ends before
	 * the first frame raises InputError (no frames is never what the user wanted). */
	mrpt::serialization::CSerializable::Ptr readObject();
	void enqueue(const mrpt::serialization::CSerializable::Ptr& o);

	std::string path_;
	TOptions opts_;
	std::unique_ptr<mrpt::io::CFileGZInputStream> file_;
	std::deque<mrpt::obs::CObservation3DRangeScan::Ptr> pending_;
	std::size_t entries_ = 0, skipped_ = 0, frames_ = 0;
	std::string imagesDir_;
};
}  // namespace mrpt_yesslam
