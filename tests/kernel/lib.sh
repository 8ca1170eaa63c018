# Shared by the kernel-tier scripts (sourced, not run): the Debian kernel of this machine's
# headers, fetched for the guest's architecture; an initramfs of busybox, the kernel modules a
# test names and the project's binaries with their libraries; a qemu boot (TCG: KVM is not
# available on CI's machines) whose serial console is turned into a pass or fail.
#
# The guest's /init prints "SMX-RESULT: <exit status of /test.sh>" and powers off; everything
# before it is the test's own output. Kernel packages and unpacked trees are cached in
# $SMX_KERNEL_CACHE (default ~/.cache/stripemux/kernel).

SMX_SKIP=77  # CTest's SKIP_RETURN_CODE
# depmod, modprobe and modinfo live in sbin, which a user's PATH may lack.
PATH=$PATH:/usr/sbin:/sbin

kernel_log() { echo "kernel: $*" >&2; }
kernel_die() {
  kernel_log "error: $*"
  exit 1
}

# kernel_init ARCH (x86_64 | aarch64): sets KVER, KDEB_ARCH, KCACHE, QEMU, and skips the test
# (exit 77) with a reason when this machine cannot run it.
kernel_init() {
  KARCH=$1
  case "$KARCH" in
    x86_64)
      KDEB_ARCH=amd64
      QEMU=qemu-system-x86_64
      ;;
    aarch64)
      KDEB_ARCH=arm64
      QEMU=qemu-system-aarch64
      ;;
    *) kernel_die "unknown guest architecture '$KARCH' (x86_64 or aarch64)" ;;
  esac
  command -v "$QEMU" >/dev/null || kernel_skip "$QEMU not installed (tools/install-deps installs it)"
  command -v apt-get >/dev/null || kernel_skip "no apt-get to fetch the Debian kernel"
  # The kernel ABI is the one whose headers are installed: out-of-tree modules build against them.
  local headers
  headers=$(find /usr/src -maxdepth 1 -name 'linux-headers-*-amd64' -printf '%f\n' | sort -V | tail -1)
  [ -n "$headers" ] || kernel_skip "no linux-headers-*-amd64 in /usr/src (tools/install-deps)"
  local abi=${headers#linux-headers-}
  abi=${abi%-amd64}
  KVER=$abi-$KDEB_ARCH
  KCACHE=${SMX_KERNEL_CACHE:-${XDG_CACHE_HOME:-${HOME:-/tmp}/.cache}/stripemux/kernel}/$KVER
  mkdir -p "$KCACHE"
}

kernel_skip() {
  echo "SKIP: $*"
  exit "$SMX_SKIP"
}

# Downloads a Debian package into the cache and unpacks it into $KCACHE/<dir>, once.
fetch_deb() {
  local package=$1 dir=$2
  [ -f "$KCACHE/$dir/.unpacked" ] && return 0
  local downloads=$KCACHE/debs
  mkdir -p "$downloads"
  # apt-get download writes into the working directory.
  (cd "$downloads" && apt-get download -q "$package" >/dev/null 2>"$downloads/apt.err") ||
    kernel_die "cannot download $package: $(tail -1 "$downloads/apt.err")"
  local deb
  deb=$(find "$downloads" -name "${package%%:*}_*.deb" | head -1)
  rm -rf "${KCACHE:?}/$dir"
  dpkg-deb -x "$deb" "$KCACHE/$dir"
  touch "$KCACHE/$dir/.unpacked"
}

# Sets KIMAGE (what qemu boots), KMODULES (the modules tree) and BUSYBOX for $KARCH.
fetch_kernel() {
  fetch_deb "linux-image-$KVER:$KDEB_ARCH" image
  KMODULES=$KCACHE/image/lib/modules/$KVER
  local vmlinuz=$KCACHE/image/boot/vmlinuz-$KVER
  if [ "$KARCH" = x86_64 ]; then
    # The bzImage's xz payload is the ELF vmlinux, which qemu enters through PVH: twice as
    # fast to boot as the bzImage, which decompresses itself under emulation.
    KIMAGE=$KCACHE/vmlinux
    if [ ! -s "$KIMAGE" ]; then
      local offset
      offset=$(LC_ALL=C grep -obUaP '\xfd7zXZ\x00' "$vmlinuz" | head -1 | cut -d: -f1)
      [ -n "$offset" ] || kernel_die "no xz payload in $vmlinuz"
      tail -c +$((offset + 1)) "$vmlinuz" | xz -dc >"$KIMAGE.tmp" 2>/dev/null || true
      [ "$(head -c 4 "$KIMAGE.tmp")" = $'\x7fELF' ] || kernel_die "cannot extract vmlinux from $vmlinuz"
      mv "$KIMAGE.tmp" "$KIMAGE"
    fi
    BUSYBOX=/bin/busybox
  else
    KIMAGE=$vmlinuz  # an uncompressed arm64 Image
    fetch_deb "busybox-static:arm64" busybox
    BUSYBOX=$KCACHE/busybox/bin/busybox
  fi
  [ -x "$BUSYBOX" ] || kernel_die "no static busybox at $BUSYBOX (busybox-static)"
}

# The shared libraries a dynamically linked binary of $KARCH loads, one path per line.
guest_libraries() {
  local binary=$1
  if [ "$KARCH" = x86_64 ]; then
    ldd "$binary" | awk '/=> \// {print $3} /^[ \t]*\/lib/ {print $1}'
  else
    # The arm64 loader lists them itself, run under qemu-user like the aarch64 tests.
    LD_TRACE_LOADED_OBJECTS=1 qemu-aarch64-static -L / "$binary" |
      awk '/=> \// {print $3} /^[ \t]*\/lib/ {print $1}'
  fi
}

# stage_root DIR: a fresh guest root with busybox and /init.
stage_root() {
  GROOT=$1
  rm -rf "$GROOT"
  mkdir -p "$GROOT"/{bin,sbin,dev,proc,sys,tmp,run,etc/modprobe.d,lib/modules/"$KVER"}
  cp "$BUSYBOX" "$GROOT/bin/busybox"
  cp "$KERNEL_DIR/guest/init" "$GROOT/init"
  chmod +x "$GROOT/init"
  : >"$GROOT/etc/smx-modules"
}

# stage_modules NAME[=PARAMS]...: the modules and everything they depend on, loaded in this
# order at boot. Modules built out of tree (gpio-sim, vimc) come from $KERNEL_EXTRA_MODULES.
stage_modules() {
  # A hard-linked copy of the kernel's modules plus the out-of-tree ones, for the host's kmod
  # to resolve dependencies in.
  local staging=$KCACHE/modules-staging
  local tree=$staging/lib/modules/$KVER
  rm -rf "$staging"
  mkdir -p "$staging/lib/modules"
  cp -al "$KMODULES" "$tree"
  if [ -n "${KERNEL_EXTRA_MODULES:-}" ]; then
    mkdir -p "$tree/extra"
    cp "$KERNEL_EXTRA_MODULES"/*.ko "$tree/extra/"
  fi
  depmod -b "$staging" "$KVER"

  local spec name file
  for spec in "$@"; do
    name=${spec%%=*}
    echo "$name" >>"$GROOT/etc/smx-modules"
    [ "$spec" = "$name" ] || echo "options $name ${spec#*=}" >>"$GROOT/etc/modprobe.d/smx.conf"
    local files
    files=$(modprobe -d "$staging" -S "$KVER" --show-depends "$name" 2>&1) ||
      kernel_die "module $name: $files"
    while read -r file; do
      local relative=${file#"$tree"/}
      mkdir -p "$GROOT/lib/modules/$KVER/$(dirname "$relative")"
      cp "$file" "$GROOT/lib/modules/$KVER/$relative"
    done < <(awk '$1 == "insmod" {print $2}' <<<"$files")
  done
  cp "$tree"/modules.order "$tree"/modules.builtin "$tree"/modules.builtin.modinfo \
    "$GROOT/lib/modules/$KVER/"
  depmod -b "$GROOT" "$KVER"
}

# Builds the modules Debian's kernel lacks (gpio-sim, vimc) for $KARCH into the cache and sets
# KERNEL_EXTRA_MODULES; fails when they cannot be built for this architecture.
build_extra_modules() {
  KERNEL_EXTRA_MODULES=$KCACHE/extra
  if [ "$KARCH" = x86_64 ]; then
    "$KERNEL_DIR/build-modules" "$KERNEL_EXTRA_MODULES" >&2
  else
    "$KERNEL_DIR/build-modules" --arch "$KDEB_ARCH" "$KERNEL_EXTRA_MODULES" >&2
  fi
}

# stage_binary PATH [GUEST_PATH]: a project binary and the shared libraries it loads.
stage_binary() {
  local binary=$1 target=${2:-/bin/$(basename "$1")}
  mkdir -p "$GROOT/$(dirname "$target")"
  cp "$binary" "$GROOT/$target"
  local library
  for library in $(guest_libraries "$binary"); do
    [ -e "$GROOT/$library" ] && continue
    mkdir -p "$GROOT/$(dirname "$library")"
    cp -L "$library" "$GROOT/$library"
  done
}

# stage_file SOURCE GUEST_PATH
stage_file() {
  mkdir -p "$GROOT/$(dirname "$2")"
  cp -r "$1" "$GROOT/$2"
}

# pack_initramfs OUT
pack_initramfs() {
  (cd "$GROOT" && find . | cpio -o -H newc --quiet | gzip -1) >"$1"
}

# run_guest INITRAMFS LOG TIMEOUT_S [QEMU ARGS...]: boots, waits for poweroff or the timeout,
# and returns 0 when the guest's test script exited 0. The console goes to LOG.
run_guest() {
  local initramfs=$1 log=$2 timeout_s=$3
  shift 3
  local console machine
  if [ "$KARCH" = x86_64 ]; then
    console=ttyS0
    machine=(-M pc -cpu max)
  else
    console=ttyAMA0
    machine=(-M virt -cpu cortex-a72)
  fi
  local start=$SECONDS
  timeout --kill-after=5 "$timeout_s" "$QEMU" "${machine[@]}" -m "${KERNEL_GUEST_MEM:-1024}" \
    -smp "${KERNEL_GUEST_CPUS:-1}" -nographic -no-reboot -kernel "$KIMAGE" -initrd "$initramfs" \
    -append "console=$console panic=-1 quiet rdinit=/init ${KERNEL_APPEND:-}" "$@" \
    </dev/null >"$log" 2>&1
  local status=$?
  tr -d '\r' <"$log" >"$log.txt"
  local result
  result=$(sed -n 's/^SMX-RESULT: \([0-9]*\).*/\1/p' "$log.txt" | tail -1)
  if [ "$status" -eq 124 ] || [ "$status" -eq 137 ]; then
    kernel_log "the guest did not finish in ${timeout_s} s; its console ended with:"
    tail -20 "$log.txt" >&2
    return 1
  fi
  if [ -z "$result" ]; then
    kernel_log "the guest stopped without a result (qemu exit $status); its console ended with:"
    tail -20 "$log.txt" >&2
    return 1
  fi
  kernel_log "guest $KARCH finished in $((SECONDS - start)) s with status $result"
  [ "$result" -eq 0 ]
}

# A free TCP port on the host's loopback, for hostfwd.
free_port() {
  python3 -c 'import socket; s = socket.socket(); s.bind(("127.0.0.1", 0)); print(s.getsockname()[1])'
}
