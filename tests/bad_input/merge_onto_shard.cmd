merge -o shard.shard1of2.exr shard.shard1of2.exr shard.shard2of2.exr
