//! Every SIMD intrinsic runs inlined into a kernel's `#[target_feature]` entry point.
//!
//! An intrinsic that ends up in code compiled without the entry point's features (a closure
//! or helper the optimiser did not inline) becomes a function call per lane operation: the
//! kernel stays correct and gets 1.5-2x slower, which no image test notices. The compiler
//! then emits the intrinsic as a function of its own, named `core::core_arch::..::_mm*`, so
//! the release binary's symbol table tells: it must hold none.

/// The names of the function symbols in an ELF64 little-endian file's `.symtab`, or `None`
/// when the file has no symbol table (stripped).
fn elf_function_symbols(elf: &[u8]) -> Option<Vec<String>> {
    let u16_at = |o: usize| u16::from_le_bytes(elf[o..o + 2].try_into().unwrap()) as usize;
    let u32_at = |o: usize| u32::from_le_bytes(elf[o..o + 4].try_into().unwrap()) as usize;
    let u64_at = |o: usize| u64::from_le_bytes(elf[o..o + 8].try_into().unwrap()) as usize;
    assert_eq!(&elf[..4], b"\x7fELF", "not an ELF file");
    assert_eq!((elf[4], elf[5]), (2, 1), "not ELF64 little-endian");
    let (shoff, shentsize, shnum) = (u64_at(0x28), u16_at(0x3a), u16_at(0x3c));
    let section = |i: usize| shoff + i * shentsize;
    let symtab = (0..shnum).find(|&i| u32_at(section(i) + 4) == 2)?;
    let (off, size) = (u64_at(section(symtab) + 24), u64_at(section(symtab) + 32));
    let strtab = section(u32_at(section(symtab) + 40));
    let strings = &elf[u64_at(strtab + 24)..][..u64_at(strtab + 32)];
    let names = elf[off..off + size]
        .chunks_exact(24)
        .filter(|sym| sym[4] & 0xf == 2) // STT_FUNC
        .map(|sym| {
            let name = &strings[u32::from_le_bytes(sym[..4].try_into().unwrap()) as usize..];
            let end = name.iter().position(|&b| b == 0).unwrap_or(name.len());
            String::from_utf8_lossy(&name[..end]).into_owned()
        })
        .collect();
    Some(names)
}

#[test]
fn no_intrinsic_is_called_out_of_line() {
    if !cfg!(all(target_arch = "x86_64", target_os = "linux")) {
        println!("skipped: the check reads an x86-64 ELF binary");
        return;
    }
    if cfg!(debug_assertions) {
        println!("skipped: an unoptimised build calls every intrinsic out of line");
        return;
    }
    let path = env!("CARGO_BIN_EXE_prism");
    let elf = std::fs::read(path).expect("the prism binary");
    let symbols = elf_function_symbols(&elf)
        .unwrap_or_else(|| panic!("{path} has no symbol table (stripped?): cannot check"));
    assert!(
        symbols.iter().any(|s| s.contains("entry_avx512")),
        "the kernels' entry points are not among the {} symbols",
        symbols.len()
    );
    // `_xgetbv` (core_arch's xsave module) is the CPU feature detection's, called once.
    let out_of_line: Vec<&String> = symbols
        .iter()
        .filter(|s| s.contains("core_arch") && s.contains("_mm"))
        .collect();
    assert!(
        out_of_line.is_empty(),
        "{} intrinsics compiled as functions of their own (a closure or helper in a kernel \
         was not inlined into its entry point; `objdump -d` shows the callers):\n{}",
        out_of_line.len(),
        out_of_line
            .iter()
            .map(|s| format!("  {s}"))
            .collect::<Vec<_>>()
            .join("\n")
    );
}
