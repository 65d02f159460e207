pm-model 3
mount equatorial
order 0
terms 6
term a 1 0 0 0
term b 2 0 0 0
term c 3 0 0 0
term d 4 0 0 0
term e 5 0 0 0
term i 6 0 0 0
end
