/* SPDX-License-Identifier: GPL-2.0-or-later
   Makes gran/hooke/stickslip and wall/gran/stickslip styles of the installed LAMMPS, which
   has no PLUGIN package and cannot be rebuilt here.

   LAMMPS creates styles through name -> creator maps (Force::pair_map, Modify::fix_map),
   filled by Force::create_factories() and Modify::create_factories(). The constructors of
   Force and Modify call those at start-up and again at every `clear`, so a style added to
   the maps once would be lost at the next `clear`. liblammps calls both functions through
   its procedure linkage table; when this library is loaded it points the library's two
   table entries at wrappers that call LAMMPS' own function and then add our styles. From
   then on every map LAMMPS builds has them: at start-up (the launcher, LD_PRELOAD), after
   `clear`, and before `read_restart`. An instance that exists already when the library is
   loaded (the stock lmp with stickslip.lmp, the python module) gets them from
   stickslip_lammps_register(), which also prints the plugin's version (the launcher
   lmp-stickslip prints it itself). */

#include "fix_wall_gran_region_stickslip.h"
#include "fix_wall_gran_stickslip.h"
#include "pair_gran_hooke_stickslip.h"

#include "comm.h"
#include "force.h"
#include "lammps.h"
#include "modify.h"
#include "stickslip_version.h"
#include "utils.h"

#include <cstring>
#include <link.h>
#include <sys/mman.h>
#include <unistd.h>

using namespace LAMMPS_NS;

namespace {

Pair *make_pair(LAMMPS *lmp) { return new StickSlip::PairGranHookeStickSlip(lmp); }

Fix *make_wall(LAMMPS *lmp, int narg, char **arg) { return new StickSlip::FixWallGranStickSlip(lmp, narg, arg); }

Fix *make_region_wall(LAMMPS *lmp, int narg, char **arg)
{
  return new StickSlip::FixWallGranRegionStickSlip(lmp, narg, arg);
}

void add_styles(Force *force) { (*force->pair_map)[StickSlip::PairGranHookeStickSlip::STYLE] = &make_pair; }

void add_styles(Modify *modify)
{
  (*modify->fix_map)[StickSlip::FixWallGranStickSlip::STYLE] = &make_wall;
  (*modify->fix_map)[StickSlip::FixWallGranRegionStickSlip::STYLE] = &make_region_wall;
}

// LAMMPS' own functions (member functions: `this` is the first argument in the C++ ABI)
void (*force_factories)(Force *) = nullptr;
void (*modify_factories)(Modify *) = nullptr;

void wrapped_force_factories(Force *force)
{
  force_factories(force);
  add_styles(force);
}

void wrapped_modify_factories(Modify *modify)
{
  modify_factories(modify);
  add_styles(modify);
}

struct Entry {
  const char *symbol;  // mangled name
  void *wrapper;
  void **original;
};

const Entry ENTRIES[] = {
    {"_ZN9LAMMPS_NS5Force16create_factoriesEv", (void *) &wrapped_force_factories, (void **) &force_factories},
    {"_ZN9LAMMPS_NS6Modify16create_factoriesEv", (void *) &wrapped_modify_factories, (void **) &modify_factories},
};
const int NENTRIES = sizeof ENTRIES / sizeof *ENTRIES;

int npatched = 0;  // entries pointed at our wrappers

/* Writes a table entry; an entry in a read-only (RELRO) page is made writable for it. */
void write_entry(void **slot, void *value, const dl_phdr_info *info)
{
  bool relro = false;
  const ElfW(Addr) at = (ElfW(Addr)) slot;
  for (int k = 0; k < info->dlpi_phnum; k++) {
    const ElfW(Phdr) &p = info->dlpi_phdr[k];
    if (p.p_type == PT_GNU_RELRO && at >= info->dlpi_addr + p.p_vaddr &&
        at < info->dlpi_addr + p.p_vaddr + p.p_memsz)
      relro = true;
  }
  const long page = sysconf(_SC_PAGESIZE);
  void *start = (void *) (at & ~(ElfW(Addr))(page - 1));
  if (relro) mprotect(start, page, PROT_READ | PROT_WRITE);
  *slot = value;
  if (relro) mprotect(start, page, PROT_READ);
}

/* dl_iterate_phdr callback: in liblammps, find the PLT relocations of ENTRIES' symbols and
   point them at the wrappers, keeping the library's own definitions as the originals. */
int patch_lammps(dl_phdr_info *info, size_t, void *)
{
  if (!info->dlpi_name || !strstr(info->dlpi_name, "liblammps.so")) return 0;
  const ElfW(Addr) base = info->dlpi_addr;
  const ElfW(Dyn) *dyn = nullptr;
  for (int k = 0; k < info->dlpi_phnum; k++)
    if (info->dlpi_phdr[k].p_type == PT_DYNAMIC) dyn = (const ElfW(Dyn) *) (base + info->dlpi_phdr[k].p_vaddr);
  if (!dyn) return 0;
  // glibc turns the dynamic section's addresses into absolute ones when it loads a library;
  // a loader that does not leaves offsets below the load address
  auto address = [base](ElfW(Addr) p) { return p < base ? p + base : p; };
  ElfW(Addr) jmprel = 0, symtab = 0, strtab = 0;
  size_t size = 0;
  for (const ElfW(Dyn) *d = dyn; d->d_tag != DT_NULL; d++) {
    if (d->d_tag == DT_JMPREL) jmprel = address(d->d_un.d_ptr);
    if (d->d_tag == DT_PLTRELSZ) size = d->d_un.d_val;
    if (d->d_tag == DT_SYMTAB) symtab = address(d->d_un.d_ptr);
    if (d->d_tag == DT_STRTAB) strtab = address(d->d_un.d_ptr);
    if (d->d_tag == DT_PLTREL && d->d_un.d_val != DT_RELA) return 1;  // (x86-64 uses RELA)
  }
  if (!jmprel || !symtab || !strtab) return 1;
  const ElfW(Rela) *rel = (const ElfW(Rela) *) jmprel;
  const ElfW(Sym) *syms = (const ElfW(Sym) *) symtab;
  const char *names = (const char *) strtab;
  for (size_t k = 0; k < size / sizeof(ElfW(Rela)); k++) {
    const ElfW(Sym) &sym = syms[ELF64_R_SYM(rel[k].r_info)];
    for (const Entry &e : ENTRIES) {
      if (strcmp(names + sym.st_name, e.symbol) != 0 || sym.st_shndx == SHN_UNDEF) continue;
      void **slot = (void **) (base + rel[k].r_offset);
      if (*slot != e.wrapper) {
        *e.original = (void *) (base + sym.st_value);
        write_entry(slot, e.wrapper, info);
      }
      npatched++;
    }
  }
  return 1;
}

void patch_once()
{
  if (npatched == 0) dl_iterate_phdr(&patch_lammps, nullptr);
}

// loading the library (launcher, LD_PRELOAD, dlopen) wraps LAMMPS' style set-up
__attribute__((constructor)) void at_load() { patch_once(); }

}  // namespace

/* Adds the styles to an existing LAMMPS instance (the python command of stickslip.lmp, the
   python module). Returns 0 when later `clear` commands keep them too, 1 when only this
   instance's current maps have them (the wrappers could not be installed). */
extern "C" __attribute__((visibility("default"))) int stickslip_lammps_register(void *lammps)
{
  patch_once();
  LAMMPS *lmp = static_cast<LAMMPS *>(lammps);
  add_styles(lmp->force);
  add_styles(lmp->modify);
  if (lmp->comm->me == 0)
    utils::logmesg(lmp, "stickslip " STICKSLIP_VERSION ": gran/hooke/stickslip, wall/gran/stickslip, "
                        "wall/gran/region/stickslip (Khellaf & Mansouri 2024)\n");
  return npatched == NENTRIES ? 0 : 1;
}
