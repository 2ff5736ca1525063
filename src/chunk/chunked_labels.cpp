// A label map block by block: table parts and shared-surface pieces, merged.
// Theory of operation: include/voxpress/chunk/chunked_labels.h.
#include "voxpress/chunk/chunked_labels.h"


#include <chrono>
#include <exception>

#include "core/timing.h"
#include "voxpress/core/error.h"
#include "core/parallel.h"

namespace voxpress {

ChunkedLabels extract_labels_chunked(const ScalarVolume& header, const BoxRead& read, const ChunkOptions& chunks,
                                     Progress* progress) {
  if (chunks.halo != 0) throw UsageError("--halo does not apply to label maps (their shared surface is pressed whole)");
  if (header.components != 1)
    throw InputError(header.source, "a layered segmentation (" + std::to_string(header.components) +
                                        " layers) is not meshed block by block: drop --chunk");
  header.lattice.validate();
  const ChunkGrid grid(header.lattice.dims, chunks);
  const auto& dims = header.lattice.dims;
  ChunkedLabels out;
  out.blocks = grid.count();
  auto t0 = std::chrono::steady_clock::now();
  std::vector<LabelTable> tables(grid.count());
  std::vector<SharedPiece> pieces(grid.count());
  std::vector<std::exception_ptr> failed(grid.count());
  {
    ProgressCounter counter(progress, "blocks", grid.count());
    detail::parallel_for(grid.count(), [&](size_t b) {
      try {
        const Box box = grid.with_halo(b), core = grid.core(b);
        ScalarVolume samples = read(box);
        if (samples.lattice.dims != box.dims() || samples.components != 1)
          throw std::logic_error("extract_labels_chunked: the reader returned the wrong box");
        samples.source = header.source;
        tables[b] = label_table_part(samples, box, core, dims);
        pieces[b] = extract_shared_piece(samples, box, core, dims);
      } catch (...) {
        failed[b] = std::current_exception();
      }
      counter.add(1);
    });
  }
  for (const std::exception_ptr& e : failed)  // the lowest block's error, whatever the schedule
    if (e) std::rethrow_exception(e);
  out.seconds_blocks = detail::seconds_since(t0);
  t0 = std::chrono::steady_clock::now();
  out.table = merge_label_tables(tables, header);
  tables = {};
  out.surface = assemble_shared_surface(header.lattice, std::move(pieces), header.source);
  out.seconds_assemble = detail::seconds_since(t0);
  return out;
}

}  // namespace voxpress
