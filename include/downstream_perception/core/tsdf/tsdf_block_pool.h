// Storage for TSDF blocks: carved from 2 MiB chunks instead of one heap allocation each. The
// integrator walks hundreds of blocks per frame; as separate 4 KB allocations each block spans
// two pages (4,104 bytes), and the page-table walks show in the frame time. A chunk is 2 MiB
// aligned and, on Linux, offered to the kernel for a transparent huge page (madvise), so ~500
// blocks share one TLB entry. Released blocks are reused before a new chunk is taken.
#pragma once

#include <cstddef>
#include <memory>
#include <vector>

namespace downstream_perception {

struct TsdfBlock;

class TsdfBlockPool {
 public:
  static constexpr std::size_t kChunkBytes = std::size_t{2} << 20;

  TsdfBlockPool() = default;
  ~TsdfBlockPool();
  TsdfBlockPool(const TsdfBlockPool&) = delete;
  TsdfBlockPool& operator=(const TsdfBlockPool&) = delete;

  /// Returns blocks to the pool that handed them out (unique_ptr deleter).
  struct Deleter {
    TsdfBlockPool* pool = nullptr;
    void operator()(TsdfBlock* block) const;
  };
  using Ptr = std::unique_ptr<TsdfBlock, Deleter>;

  /// A zeroed block (all voxels unobserved, stamp 0). Throws std::bad_alloc when no memory.
  Ptr acquire();
  /// Gives every chunk back to the system when no block is in use (a cleared map); otherwise
  /// nothing (freed blocks stay for reuse: eviction keeps the pool at the peak block count).
  void trim();
  /// Blocks a chunk holds.
  static std::size_t blocksPerChunk();
  /// Bytes taken from the system (whole chunks, used or not).
  std::size_t bytesReserved() const { return chunks_.size() * kChunkBytes; }
  std::size_t blocksInUse() const { return in_use_; }

 private:
  void release(TsdfBlock* block);
  std::vector<void*> chunks_;
  std::vector<TsdfBlock*> free_;   ///< constructed-then-destroyed slots ready for reuse
  std::size_t next_in_chunk_ = 0;  ///< slots of the newest chunk handed out so far
  std::size_t in_use_ = 0;
};

}  // namespace downstream_perception
