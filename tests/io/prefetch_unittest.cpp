// Reading ahead on a thread must not change what a source delivers: same frames, same order, the
// same error at the same position, and no hang when the reader is dropped mid-stream.
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>

#include "TestUtils.h"
#include "mrpt_yesslam/io/CPrefetchingSource.h"
#include "mrpt_yesslam/io/CTumFolderSource.h"
#include "mrpt_yesslam/io/RgbdObservation.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;
namespace fs = std::filesystem;

namespace
{
std::string rgbFile(const std::string& folder, double t)
{
	char name[64];
	std::snprintf(name, sizeof(name), "/rgb/%.6f.png", t);
	return folder + name;
}
}  // namespace

TEST(PrefetchingSource, SameFramesInTheSameOrder)
{
	TempDir d("prefetch");
	const auto frames = makeSyntheticFrames(7);
	writeTumFolder(d.path(), frames);
	for (std::size_t depth : {1u, 3u, 16u})
	{
		CTumFolderSource direct(d.path());
		CPrefetchingSource ahead(std::make_unique<CTumFolderSource>(d.path()), depth);
		EXPECT_EQ(ahead.sizeHint(), direct.sizeHint());
		EXPECT_EQ(ahead.path(), direct.path());
		for (std::size_t i = 0; i < frames.size(); i++)
		{
			auto a = ahead.next(), b = direct.next();
			ASSERT_TRUE(a && b) << "frame " << i;
			EXPECT_DOUBLE_EQ(observationTime(*a), observationTime(*b));
			EXPECT_EQ(cv::norm(a->intensityImage.asCvMatRef(), b->intensityImage.asCvMatRef(), cv::NORM_INF), 0.0);
			EXPECT_TRUE(a->rangeImage == b->rangeImage) << "frame " << i;
		}
		EXPECT_FALSE(ahead.next());
		EXPECT_FALSE(ahead.next());
	}
}

TEST(PrefetchingSource, ErrorArrivesAfterTheFramesBeforeIt)
{
	TempDir d("prefetch");
	const auto frames = makeSyntheticFrames(6);
	writeTumFolder(d.path(), frames);
	const std::string broken = rgbFile(d.path(), frames[3].tRgb);
	ASSERT_TRUE(fs::remove(broken)) << broken;
	CPrefetchingSource ahead(std::make_unique<CTumFolderSource>(d.path()), 4);
	for (int i = 0; i < 3; i++) ASSERT_TRUE(ahead.next()) << "frame " << i << " comes before the broken one";
	expectInputError([&] { ahead.next(); }, {fs::path(broken).filename().string(), "not found"});
	EXPECT_FALSE(ahead.next()) << "the stream ends after the error";
}

TEST(PrefetchingSource, DroppedMidStreamWithoutHanging)
{
	TempDir d("prefetch");
	writeTumFolder(d.path(), makeSyntheticFrames(8));
	for (int taken = 0; taken < 3; taken++)
	{
		CPrefetchingSource ahead(std::make_unique<CTumFolderSource>(d.path()), 2);
		for (int i = 0; i < taken; i++) ASSERT_TRUE(ahead.next());
	}  // the destructor joins the reader, which is blocked on a full queue or reading
}
