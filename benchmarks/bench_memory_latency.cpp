// Load-to-use latency of this machine's memory hierarchy, by working-set size: a random
// cyclic pointer chase (each load's address comes from the previous load, so the latencies
// add up and nothing overlaps). It puts numbers on the cost of the event-driven engine's cache
// misses (docs/benchmarks.md): an event touches ~15-25 lines scattered over the system.
//
// Build and run (no dependencies):
//   g++ -O2 -std=c++17 benchmarks/bench_memory_latency.cpp -o /tmp/latency && /tmp/latency
// Prints one Markdown row per working-set size: ns per dependent load, with and without
// transparent huge pages (madvise), best of 3. No assertions.
#include <sys/mman.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <random>
#include <vector>

namespace {

struct alignas(64) Line {
    Line* next;
    char pad[56];
};

double chase_ns(std::size_t bytes, bool huge) {
    const std::size_t n = bytes / sizeof(Line);
    const std::size_t size = n * sizeof(Line);
    void* mem = std::aligned_alloc(2u << 20, (size + (2u << 20) - 1) / (2u << 20) * (2u << 20));
    if (huge) madvise(mem, size, MADV_HUGEPAGE);
    else madvise(mem, size, MADV_NOHUGEPAGE);
    Line* lines = static_cast<Line*>(mem);
    std::vector<std::size_t> order(n);
    std::iota(order.begin(), order.end(), 0);
    std::shuffle(order.begin() + 1, order.end(), std::mt19937_64(7));
    for (std::size_t k = 0; k < n; ++k) lines[order[k]].next = &lines[order[(k + 1) % n]];
    Line* p = &lines[0];
    for (std::size_t k = 0; k < 2 * n; ++k) p = p->next;  // warm the caches and the TLB
    double best = 1e30;
    const std::size_t steps = std::max<std::size_t>(4 * n, 4'000'000);
    for (int rep = 0; rep < 3; ++rep) {
        const auto t0 = std::chrono::steady_clock::now();
        for (std::size_t k = 0; k < steps; ++k) p = p->next;
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        best = std::min(best, 1e9 * s / static_cast<double>(steps));
    }
    if (p == nullptr) std::puts("");  // keep the chase
    std::free(mem);
    return best;
}

}  // namespace

int main() {
    std::puts("| working set | ns/load (4 KiB pages) | ns/load (huge pages) |");
    std::puts("|---:|---:|---:|");
    for (std::size_t kib : {16, 64, 512, 1024, 1536, 3072, 8192, 16384, 65536, 262144}) {
        const std::size_t bytes = kib << 10;
        std::printf("| %zu KiB | %.1f | %.1f |\n", kib, chase_ns(bytes, false), chase_ns(bytes, true));
        std::fflush(stdout);
    }
}
