// CWorkerPool (the library's one threading mechanism) and the PNG writer built on it: order,
// results and exceptions through futures, a bounded queue that holds the producer back, and
// errors of background writes reaching the caller.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <deque>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <thread>

#include "TestUtils.h"
#include "mrpt_yesslam/util/AtomicFile.h"
#include "mrpt_yesslam/util/CAsyncPngWriter.h"
#include "mrpt_yesslam/util/CWorkerPool.h"
#include "mrpt_yesslam/util/Error.h"

using namespace mrpt_yesslam;
using namespace yesslam_test;
namespace fs = std::filesystem;

TEST(WorkerPool, OneWorkerRunsTasksInOrderAndHandsBackResultsAndErrors)
{
	CWorkerPool pool(1);
	std::vector<int> order;  // touched only by the single worker
	std::vector<std::future<int>> results;
	for (int i = 0; i < 50; i++)
		results.push_back(pool.submit(
			[i, &order]
			{
				order.push_back(i);
				if (i == 7) throw std::runtime_error("task 7 failed");
				return i * i;
			}));
	for (int i = 0; i < 50; i++)
		if (i == 7)
			EXPECT_THROW(results[static_cast<std::size_t>(i)].get(), std::runtime_error);
		else
			EXPECT_EQ(results[static_cast<std::size_t>(i)].get(), i * i);
	ASSERT_EQ(order.size(), 50u);
	for (int i = 0; i < 50; i++) EXPECT_EQ(order[static_cast<std::size_t>(i)], i);
}

TEST(WorkerPool, BoundedQueueHoldsTheProducerBack)
{
	CWorkerPool pool(1, 2);
	std::promise<void> gate;
	std::shared_future<void> open = gate.get_future().share();
	auto first = pool.submit([open] { open.wait(); });  // runs, and blocks the worker
	std::this_thread::sleep_for(std::chrono::milliseconds(50));
	pool.submit([] {});
	pool.submit([] {});  // two waiting: the queue is full
	std::atomic<bool> submitted{false};
	std::thread producer(
		[&]
		{
			pool.submit([] {}).wait();
			submitted = true;
		});
	std::this_thread::sleep_for(std::chrono::milliseconds(200));
	EXPECT_FALSE(submitted) << "a third waiting task was accepted";
	gate.set_value();
	producer.join();
	EXPECT_TRUE(submitted);
	first.get();
}

TEST(WorkerPool, SubmitIntoKeepsEveryQueuedTasksFutureAndQueuesNothingItCannotKeep)
{
	// The stages keep their tasks' futures in a deque they wait on in order (mapping, dense, loop,
	// global BA, prefetching, PNG writing); a future lost after its task was queued leaves a task
	// running that nobody waits for.
	CWorkerPool pool(1);
	std::deque<std::future<int>> futures;
	for (int i = 0; i < 5; i++) pool.submitInto(futures, [i] { return i * 10; });
	ASSERT_EQ(futures.size(), 5u);
	for (int i = 0; i < 5; i++)
	{
		EXPECT_EQ(futures.front().get(), i * 10) << "futures in submission order";
		futures.pop_front();
	}

	// A record with no room for another future: the task must not be queued.
	struct TFullRecord
	{
		std::deque<std::future<void>> d;
		void emplace_back() { throw std::length_error("no room"); }
		std::future<void>& back() { return d.back(); }
		void pop_back() { d.pop_back(); }
	} full;
	std::atomic<bool> ran{false};
	EXPECT_THROW(pool.submitInto(full, [&ran] { ran = true; }), std::length_error);
	pool.waitIdle();
	EXPECT_FALSE(ran) << "a task ran whose future had nowhere to go";

	// A task that cannot be queued (its callable fails to move into the queue): the record is as it
	// was, the futures already in it still good.
	struct TUnmovable
	{
		explicit TUnmovable(int) {}
		TUnmovable(TUnmovable&&) { throw std::runtime_error("cannot move"); }
		void operator()() const {}
	};
	std::deque<std::future<void>> record;
	pool.submitInto(record, [] {});
	EXPECT_THROW(pool.submitInto(record, TUnmovable(0)), std::runtime_error);
	ASSERT_EQ(record.size(), 1u) << "the failed task left a slot behind";
	EXPECT_NO_THROW(record.front().get());
}

TEST(WorkerPool, PngWriterWritesTheSameBytesAndReportsErrors)
{
	TempDir d("png_writer");
	cv::Mat img(48, 64, CV_16UC1);
	cv::randu(img, 0, 60000);
	writePngAtomically(d / "sync.png", img);
	std::atomic<int> after{0};
	{
		CAsyncPngWriter w(2, 4);
		for (int i = 0; i < 20; i++) w.write(d / ("a" + std::to_string(i) + ".png"), img, [&] { after++; });
		w.finish();
		EXPECT_GT(w.busySeconds(), 0.0);
	}
	EXPECT_EQ(after.load(), 20);
	auto bytes = [](const std::string& p)
	{
		std::ifstream f(p, std::ios::binary);
		return std::string((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
	};
	for (int i = 0; i < 20; i++) EXPECT_EQ(bytes(d / ("a" + std::to_string(i) + ".png")), bytes(d / "sync.png"));

	// A file that cannot be written: finish() names it; the other files are still written.
	CAsyncPngWriter w(2, 4);
	// The good file first: a write after the bad one may already raise its error (below).
	w.write(d / "ok.png", img);
	w.write(d / "no/such/folder/x.png", img);
	try
	{
		w.finish();
		ADD_FAILURE() << "no error for an unwritable path";
	}
	catch (const InputError& e)
	{
		EXPECT_NE(std::string(e.what()).find("x.png"), std::string::npos) << e.what();
	}
	EXPECT_TRUE(fs::exists(d / "ok.png"));
	// A later write raises an earlier write's error once it is done.
	CAsyncPngWriter v(1, 4);
	v.write(d / "no/such/folder/y.png", img);
	std::this_thread::sleep_for(std::chrono::milliseconds(200));
	EXPECT_THROW(v.write(d / "ok2.png", img), InputError);
	v.finish();
}
