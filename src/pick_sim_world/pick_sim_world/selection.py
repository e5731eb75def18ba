"""What a request names, checked against the scene: the instances (all when none are named)
and the parts, each once, in the order given. Raises the workspace's errors naming the field
and the value (pick_common.errors), never PyBullet's."""

from collections.abc import Iterable, Mapping

from pick_common.errors import check_int, InvalidArgument, UnknownInstance, UnknownPart


def instance_ids(instances: Iterable[int] | None, count: int) -> list[int]:
    """The instance ids named (0..count-1), each once; every instance when None."""
    if instances is None:
        return list(range(count))
    ids = []
    for value in instances:
        k = check_int('instances[]', value, low=0, high=2**32 - 1)
        if k >= count:
            raise UnknownInstance(f'instances: {k} does not exist (the scene has '
                                  f'{count}: 0..{count - 1})')
        if k not in ids:
            ids.append(k)
    return ids


def part_ids(values: Iterable[int], known: Mapping[int, int]) -> list[int]:
    """The part ids named, each once; every one of them a key of `known` (part id -> body),
    and at least one."""
    ids = []
    for value in values:
        pid = check_int('part_ids[]', value, low=0, high=2**32 - 1)
        if pid not in known:
            raise UnknownPart(f'part_ids: {pid} is not a part of this scene')
        if pid not in ids:
            ids.append(pid)
    if not ids:
        raise InvalidArgument('part_ids', [], 'is empty: name at least one part')
    return ids
