// Writes the image-based cases of the bad-input corpus (tests/bad_inputs/tum_*): small TUM folders,
// each broken in one way. The text cases beside them are written by hand. Run once; the output is
// committed. Usage: make_bad_corpus tests/bad_inputs
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <string>

namespace fs = std::filesystem;

namespace
{
void text(const fs::path& p, const std::string& s)
{
	std::ofstream f(p, std::ios::binary);
	f << s;
}

// A valid 8x6 TUM folder with two frames and a matching calibration.txt.
void validFolder(const fs::path& d)
{
	fs::create_directories(d / "rgb");
	fs::create_directories(d / "depth");
	for (int k = 0; k < 2; k++)
	{
		cv::Mat bgr(6, 8, CV_8UC3, cv::Scalar(40 * k, 90, 200));
		cv::Mat depth(6, 8, CV_16UC1, cv::Scalar(5000 + k));
		cv::imwrite((d / ("rgb/" + std::to_string(k) + ".png")).string(), bgr);
		cv::imwrite((d / ("depth/" + std::to_string(k) + ".png")).string(), depth);
	}
	text(d / "rgb.txt", "# timestamp filename\n1.000000 rgb/0.png\n1.033333 rgb/1.png\n");
	text(d / "depth.txt", "# timestamp filename\n1.004000 depth/0.png\n1.037333 depth/1.png\n");
	text(d / "calibration.txt", "# fx fy cx cy width height depth_scale\n535.4 539.2 4 3 8 6 5000\n");
}
}  // namespace

int main(int argc, char** argv)
{
	if (argc != 2)
	{
		std::fprintf(stderr, "usage: make_bad_corpus OUTPUT_FOLDER\n");
		return 1;
	}
	const fs::path out(argv[1]);
	auto make = [&](const std::string& name, const std::function<void(const fs::path&)>& damage)
	{
		const fs::path d = out / name;
		fs::remove_all(d);
		validFolder(d);
		damage(d);
	};
	make("tum_truncated_png", [](const fs::path& d) { fs::resize_file(d / "depth/0.png", 30); });
	make("tum_depth_8bit",
		 [](const fs::path& d) { cv::imwrite((d / "depth/0.png").string(), cv::Mat(6, 8, CV_8UC1, cv::Scalar(25))); });
	make("tum_depth_float_metres",
		 [](const fs::path& d)
		 {
			 cv::imwrite((d / "depth/0.tiff").string(), cv::Mat(6, 8, CV_32FC1, cv::Scalar(1.0f)));
			 fs::remove(d / "depth/0.png");
			 text(d / "depth.txt", "# timestamp filename\n1.004000 depth/0.tiff\n1.037333 depth/1.png\n");
		 });
	make("tum_wrong_size", [](const fs::path& d)
		 { cv::imwrite((d / "depth/0.png").string(), cv::Mat(3, 4, CV_16UC1, cv::Scalar(5000))); });
	make("tum_missing_image", [](const fs::path& d) { fs::remove(d / "rgb/0.png"); });
	make("tum_backwards_stamps",
		 [](const fs::path& d) { text(d / "rgb.txt", "1.033333 rgb/1.png\n1.000000 rgb/0.png\n"); });
	make("tum_no_matching_depth",
		 [](const fs::path& d) { text(d / "depth.txt", "9.0 depth/0.png\n9.1 depth/1.png\n"); });
	make("tum_empty_lists", [](const fs::path& d) { text(d / "rgb.txt", ""); });
	make("tum_no_calibration", [](const fs::path& d) { fs::remove(d / "calibration.txt"); });
	return 0;
}
