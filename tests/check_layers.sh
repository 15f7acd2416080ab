#!/bin/bash
# No include runs upward: each folder of src/ and include/accretion/ includes
# only the folders below it in this order (cmd, on top, may include any).
set -u
layers=(core scene particles counters geometry gpu lighting render io analysis)
rank() { for i in "${!layers[@]}"; do [ "${layers[$i]}" = "$1" ] && echo "$i" && return; done; echo 99; }
root=${1:-.}
bad=0
while IFS= read -r f; do
    from=$(echo "$f" | sed -E 's#^.*/(src|include/accretion)/([a-z]+)/.*#\2#')
    [ "$from" = cmd ] && continue
    for to in $(grep -oE '#include "accretion/[a-z]+/' "$f" | sed -E 's#.*accretion/([a-z]+)/#\1#' | sort -u); do
        if [ "$(rank "$to")" -gt "$(rank "$from")" ]; then
            echo "upward include: $f ($from) includes accretion/$to/"
            bad=1
        fi
    done
done < <(find "$root/src" "$root/include/accretion" -name '*.h' -o -name '*.cpp' | grep -v '/src/cmd/')
[ $bad = 0 ] && echo "layers: ${layers[*]}: no upward include"
exit $bad
