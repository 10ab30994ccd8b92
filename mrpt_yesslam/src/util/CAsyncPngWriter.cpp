#include "mrpt_yesslam/util/CAsyncPngWriter.h"

#include <algorithm>
#include <chrono>
#include <exception>

#include "mrpt_yesslam/util/AtomicFile.h"

namespace mrpt_yesslam
{
CAsyncPngWriter::CAsyncPngWriter(std::size_t threads, std::size_t maxQueued)
	: pool_(threads, std::max<std::size_t>(1, maxQueued))
{
}

CAsyncPngWriter::~CAsyncPngWriter()
{
	for (auto& f : pending_)
		if (f.valid()) f.wait();
}

void CAsyncPngWriter::write(const std::string& path, const cv::Mat& img, std::function<void()> after, int compression)
{
	// Writes already done are collected here, so that an error surfaces at the next write.
	while (!pending_.empty() && pending_.front().wait_for(std::chrono::seconds(0)) == std::future_status::ready)
	{
		auto done = std::move(pending_.front());
		pending_.pop_front();
		done.get();
	}
	pool_.submitInto(
		pending_,
		[this, path, img, after = std::move(after), compression]
		{
			const auto t0 = std::chrono::steady_clock::now();
			writePngAtomically(path, img, compression);
			if (after) after();
			busyNs_ +=
				std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now() - t0).count();
		});
}

void CAsyncPngWriter::finish()
{
	std::exception_ptr first;
	while (!pending_.empty())
	{
		auto f = std::move(pending_.front());
		pending_.pop_front();
		try
		{
			f.get();
		}
		catch (...)
		{
			if (!first) first = std::current_exception();
		}
	}
	if (first) std::rethrow_exception(first);
}
}  // namespace mrpt_yesslam
