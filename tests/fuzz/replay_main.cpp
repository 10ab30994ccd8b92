// Replays fuzz inputs (files, or every file in the folders given) through a fuzz target's
// LLVMFuzzerTestOneInput without libFuzzer: this is how the seed corpora and every crash found by
// fuzzing run as regression tests in the normal gcc build.
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size);

int main(int argc, char** argv)
{
	namespace fs = std::filesystem;
	std::size_t n = 0;
	auto run = [&](const fs::path& p)
	{
		std::ifstream f(p, std::ios::binary);
		std::vector<char> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
		LLVMFuzzerTestOneInput(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size());
		n++;
	};
	for (int i = 1; i < argc; i++)
	{
		const fs::path p(argv[i]);
		if (fs::is_directory(p))
		{
			for (const auto& e : fs::recursive_directory_iterator(p))
				if (e.is_regular_file()) run(e.path());
		}
		else if (fs::is_regular_file(p))
			run(p);
		else
		{
			std::fprintf(stderr, "replay: error: %s not found\n", argv[i]);
			return 1;
		}
	}
	if (n == 0)
	{
		std::fprintf(stderr, "replay: error: no inputs\n");
		return 1;
	}
	std::printf("replayed %zu inputs, 0 failures\n", n);
	return 0;
}
