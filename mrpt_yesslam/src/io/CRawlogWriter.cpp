#include "mrpt_yesslam/io/CRawlogWriter.h"

#include <mrpt/serialization/CArchive.h>

#include <cstdio>
#include <filesystem>

#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

namespace mrpt_yesslam
{
CRawlogWriter::CRawlogWriter(const std::string& path, int compressionLevel) : path_(path)
{
	// A link is followed; a device or pipe is written through and never renamed over (AtomicFile.h).
	const TOutputTarget target = outputTarget(path);
	target_ = target.path;
	fd_ = target.fd;
	// A descriptor (/dev/stdout): made in a temporary file and appended to it when committed, never
	// reopened by name (that would truncate a redirected file and write over what was printed).
	direct_ = target.direct && fd_ < 0;
	tmp_ = fd_ >= 0 ? makeTemporaryFile() : direct_ ? target_ : temporaryPathFor(target_);
	out_ = std::make_unique<mrpt::io::CFileGZOutputStream>();
	std::string err;
	if (!out_->open(tmp_, compressionLevel, err))
		throw InputError(path, "cannot create rawlog (" + (err.empty() ? std::string("not writable?") : err) + ")");
}

CRawlogWriter::~CRawlogWriter()
{
	if (!committed_)
	{
		out_.reset();
		if (!direct_) std::remove(tmp_.c_str());
	}
}

void CRawlogWriter::write(const mrpt::obs::CObservation& obs)
{
	try
	{
		auto arch = mrpt::serialization::archiveFrom(*out_);
		arch << obs;
	}
	catch (const std::exception& e)
	{
		throw InputError(path_, std::string("write failed (disk full?): ") + e.what());
	}
	count_++;
}

std::uintmax_t CRawlogWriter::commit()
{
	out_->close();
	std::error_code ec;
	committed_ = true;
	if (direct_) return 0;
	if (fd_ >= 0)
	{
		const auto size = std::filesystem::file_size(tmp_, ec);
		try
		{
			appendFileToDescriptor(tmp_, fd_, path_);
		}
		catch (...)
		{
			std::remove(tmp_.c_str());
			throw;
		}
		std::remove(tmp_.c_str());
		return ec ? 0 : size;
	}
	std::filesystem::rename(tmp_, target_, ec);
	if (ec)
	{
		committed_ = false;
		throw InputError(path_, "cannot move the finished rawlog into place (" + ec.message() + ")");
	}
	const auto sz = std::filesystem::file_size(target_, ec);
	return ec ? 0 : sz;
}
}  // namespace mrpt_yesslam
