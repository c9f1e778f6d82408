#!/bin/sh
# rustc wrapper (see config.toml): `static-bin.sh RUSTC ARGS...` runs `RUSTC ARGS...`, adding
# `-C target-feature=+crt-static` when ARGS build the `raytty` binary (not its tests) for
# x86_64-unknown-linux-gnu and the C library's static archive is there to link with.
# Anything else runs unchanged.
is_bin=0 name=0 target="" want_target=0
for a in "$@"; do
    if [ "$want_target" = 1 ]; then target=$a; want_target=0; continue; fi
    case $a in
        --test) exec "$@" ;;
        --crate-type=bin) is_bin=1 ;;
        --target) want_target=1 ;;
        --target=*) target=${a#--target=} ;;
    esac
    if [ "$prev" = --crate-name ] && [ "$a" = raytty ]; then name=1; fi
    if [ "$prev" = --crate-type ] && [ "$a" = bin ]; then is_bin=1; fi
    prev=$a
done
if [ "$name$is_bin" != 11 ]; then exec "$@"; fi
if [ -z "$target" ]; then
    target=$("$1" -vV 2>/dev/null | sed -n 's/^host: //p')
fi
if [ "$target" = x86_64-unknown-linux-gnu ] &&
    [ -f "$(${CC:-cc} -print-file-name=libc.a 2>/dev/null)" ]; then
    exec "$@" -C target-feature=+crt-static
fi
exec "$@"
