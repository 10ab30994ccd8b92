// Atomic output never replaces what is not a regular file (issue 18, item 1): a symbolic link is
// followed and its target replaced (the link stays a link), a FIFO is written through (a reader
// gets the bytes, the FIFO stays a FIFO), a directory is refused with one line; a regular file is
// still replaced atomically, leaving no temporary file behind.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <future>
#include <sstream>

#include "TestUtils.h"
#include "mrpt_yesslam/io/CRawlogWriter.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;
namespace fs = std::filesystem;

TEST(AtomicFile, RegularFileIsReplacedWithoutLeftovers)
{
	TempDir d("atomic_regular");
	writeFileAtomically(d / "a.txt", std::string("old"));
	writeFileAtomically(d / "a.txt", std::string("new"));
	EXPECT_EQ(readText(d / "a.txt"), "new");
	std::size_t entries = 0;
	for (const auto& e : fs::directory_iterator(d.path())) entries += e.path().filename() != "";
	EXPECT_EQ(entries, 1u);
}

TEST(AtomicFile, ASymlinkIsFollowedAndKept)
{
	TempDir d("atomic_link");
	fs::create_directories(d / "data");
	writeFileAtomically(d / "data/target.txt", std::string("old"));
	fs::create_symlink("data/target.txt", d / "link.txt");  // relative, as users make them
	writeFileAtomically(d / "link.txt", std::string("through the link"));
	EXPECT_TRUE(fs::is_symlink(fs::symlink_status(d / "link.txt")));
	EXPECT_EQ(readText(d / "data/target.txt"), "through the link");
	// A dangling link: its target is created.
	fs::create_symlink(d / "data/new.txt", d / "dangling.txt");
	writeFileAtomically(d / "dangling.txt", std::string("created"));
	EXPECT_TRUE(fs::is_symlink(fs::symlink_status(d / "dangling.txt")));
	EXPECT_EQ(readText(d / "data/new.txt"), "created");
	// A rawlog through a link too.
	fs::create_symlink("data/out.rawlog", d / "out.rawlog");
	{
		CRawlogWriter w(d / "out.rawlog");
		w.commit();
	}
	EXPECT_TRUE(fs::is_symlink(fs::symlink_status(d / "out.rawlog")));
	EXPECT_TRUE(fs::is_regular_file(d / "data/out.rawlog"));
}

TEST(AtomicFile, AFifoIsWrittenThroughNotReplaced)
{
	TempDir d("atomic_fifo");
	const std::string fifo = d / "pipe";
	ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
	auto reader = std::async(std::launch::async, [&] { return readText(fifo); });
	writeFileAtomically(fifo, std::string("to the reader"));
	EXPECT_EQ(reader.get(), "to the reader");
	EXPECT_TRUE(fs::is_fifo(fs::symlink_status(fifo)));
	std::size_t entries = 0;
	for (const auto& e : fs::directory_iterator(d.path())) entries += e.path().filename() != "";
	EXPECT_EQ(entries, 1u) << "no temporary file beside the FIFO";
}

TEST(AtomicFile, ADeviceIsWrittenThroughNotReplaced)
{
	// /dev/null is a character device: writing succeeds and it stays one (a rename over it would
	// replace the device for the whole machine when run as root).
	writeFileAtomically("/dev/null", std::string("discarded"));
	EXPECT_TRUE(fs::is_character_file("/dev/null"));
	EXPECT_FALSE(outputTarget("/dev/null").path.empty());
	EXPECT_TRUE(outputTarget("/dev/null").direct);
}

TEST(AtomicFile, ADirectoryIsRefusedWithOneLine)
{
	TempDir d("atomic_dir");
	fs::create_directories(d / "sub");
	try
	{
		writeFileAtomically(d / "sub", std::string("x"));
		FAIL() << "expected InputError";
	}
	catch (const InputError& e)
	{
		const std::string msg = e.what();
		EXPECT_NE(msg.find("sub"), std::string::npos) << msg;
		EXPECT_NE(msg.find("directory"), std::string::npos) << msg;
		EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
	}
	EXPECT_TRUE(fs::is_directory(d / "sub"));
}

// Issue 43 item 5: an output named by one of our descriptors (/dev/stdout redirected to a file,
// /proc/self/fd/N) is written at the descriptor, after what was written there: not reopened,
// truncated or replaced. The same for a rawlog recorded there.
TEST(AtomicFile, ADescriptorOfOursIsWrittenAfterWhatItHolds)
{
	TempDir d("atomic_fd");
	const std::string file = d / "out.txt";
	const int fd = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
	ASSERT_GE(fd, 0);
	ASSERT_EQ(::write(fd, "lines\n", 6), 6);
	const std::string name = "/proc/self/fd/" + std::to_string(fd);
	EXPECT_EQ(outputTarget(name).fd, fd);
	EXPECT_EQ(outputTarget("/dev/stdout").fd, 1);
	EXPECT_EQ(outputTarget("/dev/fd/2").fd, 2);
	writeFileAtomically(name, std::string("{\"json\": 1}\n"));
	{
		CRawlogWriter w(name);
		EXPECT_GT(w.commit(), 0u);  // an empty rawlog still has its gzip header
	}
	::close(fd);
	const std::string text = readText(file);
	EXPECT_EQ(text.rfind("lines\n{\"json\": 1}\n", 0), 0u) << text.substr(0, 40);
	EXPECT_GT(text.size(), 20u) << "the rawlog follows";
	EXPECT_TRUE(fs::is_regular_file(file));
	for (const auto& e : fs::directory_iterator(d.path()))
		EXPECT_EQ(e.path().filename(), "out.txt") << "no temporary file left";
}
