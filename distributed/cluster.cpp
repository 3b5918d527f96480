#include "distributed/cluster.h"

#include <algorithm>
#include <cstdlib>
#include <vector>

#ifdef EMBER_HAVE_MPI
#include <mpi.h>
#endif

namespace ember {

namespace {

bool launchedByMpi() {
  for (const char* var : {"OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK", "MPI_LOCALNRANKS"})
    if (std::getenv(var)) return true;
  return false;
}

#ifdef EMBER_HAVE_MPI
// The AOV sums can pass MPI's int count (13 doubles per pixel): sent in pieces of at most 2^30.
constexpr size_t kChunk = size_t(1) << 30;

void sendInChunks(const std::vector<double>& values, int tag) {
  for (size_t at = 0; at < values.size(); at += kChunk)
    MPI_Send(values.data() + at, int(std::min(kChunk, values.size() - at)), MPI_DOUBLE, 0, tag,
             MPI_COMM_WORLD);
}

void receiveInChunks(std::vector<double>& values, int from, int tag) {
  for (size_t at = 0; at < values.size(); at += kChunk)
    MPI_Recv(values.data() + at, int(std::min(kChunk, values.size() - at)), MPI_DOUBLE, from, tag,
             MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}
#endif

}  // namespace

bool clusterSupport() {
#ifdef EMBER_HAVE_MPI
  return true;
#else
  return false;
#endif
}

Cluster& Cluster::instance() {
  static Cluster cluster;
  return cluster;
}

Cluster::Cluster() {
#ifdef EMBER_HAVE_MPI
  if (!launchedByMpi()) return;
  int provided = 0;
  // Only the main thread calls MPI; oneTBB's workers never do.
  MPI_Init_thread(nullptr, nullptr, MPI_THREAD_FUNNELED, &provided);
  initialised_ = true;
  MPI_Comm_rank(MPI_COMM_WORLD, &rank_);
  MPI_Comm_size(MPI_COMM_WORLD, &size_);
#else
  (void)launchedByMpi;
#endif
}

Cluster::~Cluster() {
#ifdef EMBER_HAVE_MPI
  if (initialised_) MPI_Finalize();
#endif
}

Cluster::Share Cluster::shareOf(int count) const {
  const int base = count / size_, extra = count % size_;
  const uint64_t offset = uint64_t(rank_) * uint64_t(base) + uint64_t(std::min(rank_, extra));
  return {offset, base + (rank_ < extra ? 1 : 0)};
}

void Cluster::reduceToRoot(Film& film) const {
  if (size_ == 1) return;
#ifdef EMBER_HAVE_MPI
  const int n = int(film.pixelCount());
  if (rank_ != 0) {
    MPI_Send(film.sums().data(), 3 * n, MPI_DOUBLE, 0, 0, MPI_COMM_WORLD);
    MPI_Send(film.sumsOfSquares().data(), 3 * n, MPI_DOUBLE, 0, 1, MPI_COMM_WORLD);
    MPI_Send(film.counts().data(), n, MPI_UINT32_T, 0, 2, MPI_COMM_WORLD);
    sendInChunks(film.aovSums(), 3);
    return;
  }
  const size_t pixels = static_cast<size_t>(n);
  std::vector<glm::dvec3> sums(pixels), squares(pixels);
  std::vector<uint32_t> counts(pixels);
  std::vector<double> aovs(film.aovSums().size());
  for (int r = 1; r < size_; ++r) {
    MPI_Recv(sums.data(), 3 * n, MPI_DOUBLE, r, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    MPI_Recv(squares.data(), 3 * n, MPI_DOUBLE, r, 1, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    MPI_Recv(counts.data(), n, MPI_UINT32_T, r, 2, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
    receiveInChunks(aovs, r, 3);
    for (size_t i = 0; i < aovs.size(); ++i) film.aovSums()[i] += aovs[i];
    for (size_t i = 0; i < pixels; ++i) {
      film.sums()[i] += sums[i];
      film.sumsOfSquares()[i] += squares[i];
      film.counts()[i] += counts[i];
    }
  }
#endif
}

uint64_t Cluster::sum(uint64_t value) const {
  if (size_ == 1) return value;
#ifdef EMBER_HAVE_MPI
  uint64_t all = 0;
  MPI_Allreduce(&value, &all, 1, MPI_UINT64_T, MPI_SUM, MPI_COMM_WORLD);
  return all;
#else
  return value;
#endif
}

bool Cluster::any(bool flag) const {
  if (size_ == 1) return flag;
#ifdef EMBER_HAVE_MPI
  int mine = flag ? 1 : 0, all = 0;
  MPI_Allreduce(&mine, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return all != 0;
#else
  return flag;
#endif
}

}  // namespace ember
